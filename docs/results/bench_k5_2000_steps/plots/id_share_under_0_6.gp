# gnuplot id_share_under_0_6.gp (run in this directory) draws id_share_under_0_6.png, id_share_under_0_6.svg and id_share_under_0_6.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "id_share_under_0_6.png"
set multiplot layout 1,1 title "id_share_under_0_6 against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of renders under 0.6 from own neutral"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_share_under_0_6.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "id_share_under_0_6.svg"
set multiplot layout 1,1 title "id_share_under_0_6 against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of renders under 0.6 from own neutral"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_share_under_0_6.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "id_share_under_0_6.pdf"
set multiplot layout 1,1 title "id_share_under_0_6 against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "share of renders under 0.6 from own neutral"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'id_share_under_0_6.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
