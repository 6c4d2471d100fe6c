set terminal pngcairo size 1200,650
set output 'intervals_snr50_seed1.png'
set title 'Paper 001 example, N = 1000, SNR 50 dB, seed 1: intervals minus truth'
set ylabel '(value - truth) / paper half-width'
set termoption noenhanced
set offsets 0.6, 0.6, 0, 0
set xtics rotate by -45
set grid ytics
set key outside right
set xzeroaxis lt -1
plot 'intervals_snr50_seed1.dat' using ($1-0.3):(($3+$4)/2):3:4:xtic(2) with yerrorbars pt 0 lw 3 lc rgb 'forest-green' title 'inner hull', '' using ($1-0.1):(($5+$6)/2):5:6 with yerrorbars pt 0 lw 2 lc rgb 'black' title 'paper (delta = 3)', '' using ($1+0.10):(($7+$8)/2):7:8 with yerrorbars pt 0 lw 2 lc rgb 'royalblue' title 'outer, delta = 2'
