# ant_acrobatic: median and 25-75% band over seeds. Redraw here with: gnuplot compare.gp
set terminal pngcairo size 1400,900 font ',10'
set output 'compare.png.tmp'
set termoption noenhanced
set style fill transparent solid 0.2 noborder
set grid
set key bottom right
set multiplot layout 2,2 title 'ant_acrobatic: median and 25-75% over 2 seeds per method'
set title 'training return (trailing mean of 5 updates)'
set xlabel 'env steps (millions)'
plot 'curves/return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' title 'sasa'
set title 'evaluation return (policy mean)'
set xlabel 'env steps (millions)'
plot 'curves/eval_return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/eval_return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle
set title 'evaluation pole_up_s'
set xlabel 'env steps (millions)'
plot 'curves/eval_pole_up_s_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/eval_pole_up_s_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle
set title 'training return against wall-clock time (one core per run)'
set xlabel 'minutes'
plot 'curves/return_sasa.dat' using ($2/60):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/return_sasa.dat' using ($2/60):3 with lines lw 2 lc rgb '#2ca02c' notitle
unset multiplot
set output
system('mv -f compare.png.tmp compare.png')
