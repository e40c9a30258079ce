# gnuplot id_distance_reference.gp (run in this directory) draws id_distance_reference.png, id_distance_reference.svg and id_distance_reference.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "id_distance_reference.png"
set multiplot layout 1,1 title "id_distance_reference against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "ground truth's own distance to its neutral (reference)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance_reference.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "id_distance_reference.svg"
set multiplot layout 1,1 title "id_distance_reference against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "ground truth's own distance to its neutral (reference)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance_reference.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "id_distance_reference.pdf"
set multiplot layout 1,1 title "id_distance_reference against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "ground truth's own distance to its neutral (reference)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance_reference.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
