# gnuplot expr_gain.gp (run in this directory) draws expr_gain.png and expr_gain.svg
set terminal pngcairo noenhanced size 1220,480 font "sans,9"
set output "expr_gain.png"
set multiplot layout 1,3 title "expr_gain against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of the true expression change reproduced (1 = all, 0 = none)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'expr_gain.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'expr_gain.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'expr_gain.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
set terminal svg noenhanced size 1220,480 font "sans,9"
set output "expr_gain.svg"
set multiplot layout 1,3 title "expr_gain against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of the true expression change reproduced (1 = all, 0 = none)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'expr_gain.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'expr_gain.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'expr_gain.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'expr_gain.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'expr_gain.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'expr_gain.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'expr_gain.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
