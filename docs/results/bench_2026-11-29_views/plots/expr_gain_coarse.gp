# gnuplot expr_gain_coarse.gp (run in this directory) draws expr_gain_coarse.png and expr_gain_coarse.svg
set terminal pngcairo noenhanced size 1220,480 font "sans,9"
set output "expr_gain_coarse.png"
set multiplot layout 1,3 title "expr_gain_coarse against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of the expression change reproduced, low-passed 2 px at 128 (1 = all)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'expr_gain_coarse.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain_coarse.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain_coarse.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain_coarse.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain_coarse.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'expr_gain_coarse.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain_coarse.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain_coarse.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain_coarse.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain_coarse.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'expr_gain_coarse.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain_coarse.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain_coarse.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain_coarse.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain_coarse.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
set terminal svg noenhanced size 1220,480 font "sans,9"
set output "expr_gain_coarse.svg"
set multiplot layout 1,3 title "expr_gain_coarse against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of the expression change reproduced, low-passed 2 px at 128 (1 = all)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'expr_gain_coarse.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain_coarse.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain_coarse.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain_coarse.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain_coarse.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'expr_gain_coarse.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain_coarse.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain_coarse.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain_coarse.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain_coarse.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'expr_gain_coarse.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain_coarse.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain_coarse.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain_coarse.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain_coarse.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
