# gnuplot id_distance_gt.gp (run in this directory) draws id_distance_gt.png, id_distance_gt.svg and id_distance_gt.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "id_distance_gt.png"
set multiplot layout 1,1 title "id_distance_gt against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity distance to ground truth (lower = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance_gt.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "id_distance_gt.svg"
set multiplot layout 1,1 title "id_distance_gt against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity distance to ground truth (lower = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance_gt.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "id_distance_gt.pdf"
set multiplot layout 1,1 title "id_distance_gt against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity distance to ground truth (lower = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance_gt.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
