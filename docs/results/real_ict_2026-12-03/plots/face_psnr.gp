# gnuplot face_psnr.gp (run in this directory) draws face_psnr.png, .svg and .pdf
set terminal pngcairo noenhanced size 640,420 font "sans,9"
set output "face_psnr.png"
set xlabel "K (training frames)"
set ylabel "face PSNR against the held-out photo (dB, higher = better)"
set grid
set key below
set xtics (3, 5, 10)
set offsets 0.3, 0.3, 0, 0
plot 'face_psnr.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title "cap4d-felix / icef-prior", 'face_psnr.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title "smirk-skarsgard / icef-prior"
set terminal svg noenhanced size 640,420 font "sans,9"
set output "face_psnr.svg"
set xlabel "K (training frames)"
set ylabel "face PSNR against the held-out photo (dB, higher = better)"
set grid
set key below
set xtics (3, 5, 10)
set offsets 0.3, 0.3, 0, 0
plot 'face_psnr.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title "cap4d-felix / icef-prior", 'face_psnr.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title "smirk-skarsgard / icef-prior"
set terminal pdfcairo noenhanced size 4.3in,2.8in font "sans,7"
set output "face_psnr.pdf"
set xlabel "K (training frames)"
set ylabel "face PSNR against the held-out photo (dB, higher = better)"
set grid
set key below
set xtics (3, 5, 10)
set offsets 0.3, 0.3, 0, 0
plot 'face_psnr.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title "cap4d-felix / icef-prior", 'face_psnr.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title "smirk-skarsgard / icef-prior"
unset output
