# gnuplot real_expr_gain.gp (run in this directory) draws real_expr_gain.png, .svg and .pdf
set terminal pngcairo noenhanced size 640,420 font "sans,9"
set output "real_expr_gain.png"
set xlabel "K (training frames)"
set ylabel "real_expr_gain (1 = the tracked expression closes the gap, 0 = no change)"
set grid
set key below
set xtics (3, 5, 10)
set offsets 0.3, 0.3, 0, 0
plot 'real_expr_gain.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title "cap4d-felix / icef-prior", 'real_expr_gain.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title "smirk-skarsgard / icef-prior"
set terminal svg noenhanced size 640,420 font "sans,9"
set output "real_expr_gain.svg"
set xlabel "K (training frames)"
set ylabel "real_expr_gain (1 = the tracked expression closes the gap, 0 = no change)"
set grid
set key below
set xtics (3, 5, 10)
set offsets 0.3, 0.3, 0, 0
plot 'real_expr_gain.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title "cap4d-felix / icef-prior", 'real_expr_gain.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title "smirk-skarsgard / icef-prior"
set terminal pdfcairo noenhanced size 4.3in,2.8in font "sans,7"
set output "real_expr_gain.pdf"
set xlabel "K (training frames)"
set ylabel "real_expr_gain (1 = the tracked expression closes the gap, 0 = no change)"
set grid
set key below
set xtics (3, 5, 10)
set offsets 0.3, 0.3, 0, 0
plot 'real_expr_gain.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title "cap4d-felix / icef-prior", 'real_expr_gain.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title "smirk-skarsgard / icef-prior"
unset output
