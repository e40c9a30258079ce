# gnuplot ssim.gp (run in this directory) draws ssim.png, ssim.svg and ssim.pdf
set terminal pngcairo noenhanced size 460,480 font "sans,9"
set output "ssim.png"
set multiplot layout 1,1 title "ssim against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "SSIM (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'ssim.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal svg noenhanced size 460,480 font "sans,9"
set output "ssim.svg"
set multiplot layout 1,1 title "ssim against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "SSIM (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'ssim.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
set terminal pdfcairo noenhanced size 3.07in,3.20in font "sans,7"
set output "ssim.pdf"
set multiplot layout 1,1 title "ssim against delta (mean +- std over 3 identities)"
set xlabel "delta (distance to the nearest training expression)"
set ylabel "SSIM (higher = better)"
set grid
set key below horizontal box
set offsets 0.05, 0.05, 0, 0
set title "K = 5"
plot 'ssim.dat' index 0 using 1:2:3 with yerrorlines lw 2 pt 7 title "icef-prior"
unset multiplot
unset output
