# gnuplot id_distance_reference.gp (run in this directory) draws id_distance_reference.png and id_distance_reference.svg
set terminal pngcairo noenhanced size 1220,480 font "sans,9"
set output "id_distance_reference.png"
set multiplot layout 1,3 title "id_distance_reference against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "ground truth's own distance to its neutral (reference)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'id_distance_reference.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_distance_reference.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_distance_reference.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_distance_reference.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_distance_reference.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'id_distance_reference.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_distance_reference.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_distance_reference.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_distance_reference.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_distance_reference.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'id_distance_reference.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_distance_reference.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_distance_reference.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_distance_reference.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_distance_reference.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
set terminal svg noenhanced size 1220,480 font "sans,9"
set output "id_distance_reference.svg"
set multiplot layout 1,3 title "id_distance_reference against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "ground truth's own distance to its neutral (reference)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'id_distance_reference.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_distance_reference.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_distance_reference.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_distance_reference.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_distance_reference.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'id_distance_reference.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_distance_reference.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_distance_reference.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_distance_reference.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_distance_reference.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'id_distance_reference.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'id_distance_reference.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'id_distance_reference.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'id_distance_reference.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'id_distance_reference.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
