# a1_beam: median and 25-75% band over seeds. Redraw here with: gnuplot compare.gp
set terminal pngcairo size 1400,1350 font ',10'
set output 'compare.png.tmp'
set termoption noenhanced
set style fill transparent solid 0.2 noborder
set grid
set key bottom right
set multiplot layout 3,2 title 'a1_beam: median and 25-75% over 2 seeds per method'
set title 'training return (trailing mean of 5 updates)'
set xlabel 'env steps (millions)'
plot 'curves/return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' title 'masa'
set title 'evaluation return (policy mean)'
set xlabel 'env steps (millions)'
plot 'curves/eval_return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/eval_return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle
set title 'evaluation distance_m'
set xlabel 'env steps (millions)'
plot 'curves/eval_distance_m_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/eval_distance_m_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle
set title 'evaluation speed_mps'
set xlabel 'env steps (millions)'
plot 'curves/eval_speed_mps_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/eval_speed_mps_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle
set title 'training return against wall-clock time (one core per run)'
set xlabel 'minutes'
plot 'curves/return_masa.dat' using ($2/60):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/return_masa.dat' using ($2/60):3 with lines lw 2 lc rgb '#d62728' notitle
unset multiplot
set output
system('mv -f compare.png.tmp compare.png')
