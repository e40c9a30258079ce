# gnuplot expr_corr.gp (run in this directory) draws expr_corr.png, expr_corr.svg and expr_corr.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "expr_corr.png"
set multiplot layout 1,1 title "expr_corr against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "cosine of the render's change with the true change (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'expr_corr.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "expr_corr.svg"
set multiplot layout 1,1 title "expr_corr against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "cosine of the render's change with the true change (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'expr_corr.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "expr_corr.pdf"
set multiplot layout 1,1 title "expr_corr against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "cosine of the render's change with the true change (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'expr_corr.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
