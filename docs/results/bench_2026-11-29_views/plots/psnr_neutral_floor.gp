# gnuplot psnr_neutral_floor.gp (run in this directory) draws psnr_neutral_floor.png and psnr_neutral_floor.svg
set terminal pngcairo noenhanced size 1220,480 font "sans,9"
set output "psnr_neutral_floor.png"
set multiplot layout 1,3 title "psnr_neutral_floor against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "PSNR of the ground-truth neutral, dB (a face that does not move)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'psnr_neutral_floor.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'psnr_neutral_floor.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'psnr_neutral_floor.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'psnr_neutral_floor.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'psnr_neutral_floor.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'psnr_neutral_floor.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'psnr_neutral_floor.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'psnr_neutral_floor.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'psnr_neutral_floor.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'psnr_neutral_floor.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'psnr_neutral_floor.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'psnr_neutral_floor.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'psnr_neutral_floor.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'psnr_neutral_floor.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'psnr_neutral_floor.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
set terminal svg noenhanced size 1220,480 font "sans,9"
set output "psnr_neutral_floor.svg"
set multiplot layout 1,3 title "psnr_neutral_floor against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "PSNR of the ground-truth neutral, dB (a face that does not move)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'psnr_neutral_floor.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'psnr_neutral_floor.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'psnr_neutral_floor.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'psnr_neutral_floor.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'psnr_neutral_floor.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'psnr_neutral_floor.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'psnr_neutral_floor.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'psnr_neutral_floor.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'psnr_neutral_floor.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'psnr_neutral_floor.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'psnr_neutral_floor.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'psnr_neutral_floor.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'psnr_neutral_floor.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'psnr_neutral_floor.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'psnr_neutral_floor.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
