# gnuplot ssim.gp (run in this directory) draws ssim.png and ssim.svg
set terminal pngcairo noenhanced size 1220,480 font "sans,9"
set output "ssim.png"
set multiplot layout 1,3 title "ssim against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "SSIM (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'ssim.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'ssim.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'ssim.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'ssim.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'ssim.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'ssim.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'ssim.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'ssim.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'ssim.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'ssim.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'ssim.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'ssim.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'ssim.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'ssim.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'ssim.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
set terminal svg noenhanced size 1220,480 font "sans,9"
set output "ssim.svg"
set multiplot layout 1,3 title "ssim against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "SSIM (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 3"
plot 'ssim.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'ssim.dat' index 1 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'ssim.dat' index 2 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'ssim.dat' index 3 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'ssim.dat' index 4 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 5"
plot 'ssim.dat' index 5 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'ssim.dat' index 6 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'ssim.dat' index 7 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'ssim.dat' index 8 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'ssim.dat' index 9 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
set title "K = 10"
plot 'ssim.dat' index 10 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef", 'ssim.dat' index 11 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp", 'ssim.dat' index 12 using 1:2:3 with yerrorlines lw 2 pt 7 title "nerface", 'ssim.dat' index 13 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior", 'ssim.dat' index 14 using 1:2:3 with yerrorlines lw 2 pt 7 title "warp-prior"
unset multiplot
