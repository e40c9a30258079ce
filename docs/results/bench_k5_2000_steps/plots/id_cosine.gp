# gnuplot id_cosine.gp (run in this directory) draws id_cosine.png, id_cosine.svg and id_cosine.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "id_cosine.png"
set multiplot layout 1,1 title "id_cosine against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity cosine to own neutral render (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_cosine.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "id_cosine.svg"
set multiplot layout 1,1 title "id_cosine against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity cosine to own neutral render (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_cosine.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "id_cosine.pdf"
set multiplot layout 1,1 title "id_cosine against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity cosine to own neutral render (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_cosine.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
