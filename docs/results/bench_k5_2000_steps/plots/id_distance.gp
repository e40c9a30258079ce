# gnuplot id_distance.gp (run in this directory) draws id_distance.png, id_distance.svg and id_distance.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "id_distance.png"
set multiplot layout 1,1 title "id_distance against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity distance to own neutral render"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "id_distance.svg"
set multiplot layout 1,1 title "id_distance against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity distance to own neutral render"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "id_distance.pdf"
set multiplot layout 1,1 title "id_distance against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "identity distance to own neutral render"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_distance.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
