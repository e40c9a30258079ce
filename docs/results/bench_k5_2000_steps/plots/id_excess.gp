# gnuplot id_excess.gp (run in this directory) draws id_excess.png, id_excess.svg and id_excess.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "id_excess.png"
set multiplot layout 1,1 title "id_excess against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "drift beyond the ground truth's own (0 = as the truth; < 0 = under-expression)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_excess.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "id_excess.svg"
set multiplot layout 1,1 title "id_excess against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "drift beyond the ground truth's own (0 = as the truth; < 0 = under-expression)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_excess.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "id_excess.pdf"
set multiplot layout 1,1 title "id_excess against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "drift beyond the ground truth's own (0 = as the truth; < 0 = under-expression)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_excess.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
