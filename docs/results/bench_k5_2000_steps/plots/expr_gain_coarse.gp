# gnuplot expr_gain_coarse.gp (run in this directory) draws expr_gain_coarse.png, expr_gain_coarse.svg and expr_gain_coarse.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "expr_gain_coarse.png"
set multiplot layout 1,1 title "expr_gain_coarse against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of the expression change reproduced, low-passed 2 px at 128 (1 = all)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'expr_gain_coarse.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "expr_gain_coarse.svg"
set multiplot layout 1,1 title "expr_gain_coarse against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of the expression change reproduced, low-passed 2 px at 128 (1 = all)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'expr_gain_coarse.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "expr_gain_coarse.pdf"
set multiplot layout 1,1 title "expr_gain_coarse against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of the expression change reproduced, low-passed 2 px at 128 (1 = all)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'expr_gain_coarse.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
