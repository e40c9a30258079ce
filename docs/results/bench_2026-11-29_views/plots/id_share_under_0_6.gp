# gnuplot id_share_under_0_6.gp (run in this directory) draws id_share_under_0_6.png and id_share_under_0_6.svg
set terminal pngcairo noenhanced size 1220,480 font "sans,9"
set output "id_share_under_0_6.png"
set multiplot layout 1,3 title "id_share_under_0_6 against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of renders under 0.6 from own neutral"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'id_share_under_0_6.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_share_under_0_6.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_share_under_0_6.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_share_under_0_6.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_share_under_0_6.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'id_share_under_0_6.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_share_under_0_6.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_share_under_0_6.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_share_under_0_6.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_share_under_0_6.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'id_share_under_0_6.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_share_under_0_6.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_share_under_0_6.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_share_under_0_6.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_share_under_0_6.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
set terminal svg noenhanced size 1220,480 font "sans,9"
set output "id_share_under_0_6.svg"
set multiplot layout 1,3 title "id_share_under_0_6 against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of renders under 0.6 from own neutral"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'id_share_under_0_6.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_share_under_0_6.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_share_under_0_6.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_share_under_0_6.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_share_under_0_6.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'id_share_under_0_6.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_share_under_0_6.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_share_under_0_6.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_share_under_0_6.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_share_under_0_6.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'id_share_under_0_6.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_share_under_0_6.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_share_under_0_6.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_share_under_0_6.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_share_under_0_6.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
