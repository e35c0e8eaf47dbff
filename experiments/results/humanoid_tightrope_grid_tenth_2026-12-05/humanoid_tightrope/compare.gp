# humanoid_tightrope: median and 25-75% band over seeds. Redraw here with: gnuplot compare.gp
set terminal pngcairo size 1400,1350 font ',10'
set output 'compare.png.tmp'
set termoption noenhanced
set style fill transparent solid 0.2 noborder
set grid
set key bottom right
set multiplot layout 3,2 title 'humanoid_tightrope: median and 25-75% over 5 seeds per method'
set title 'training return (trailing mean of 5 updates)'
set xlabel 'env steps (millions)'
plot 'curves/return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' title 'masa', \
     'curves/return_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'curves/return_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' title 'sa', \
     'curves/return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' title 'sasa', \
     'curves/return_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'curves/return_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' title 'ma'
set title 'evaluation return (policy mean)'
set xlabel 'env steps (millions)'
plot 'curves/eval_return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/eval_return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'curves/eval_return_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'curves/eval_return_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'curves/eval_return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/eval_return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'curves/eval_return_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'curves/eval_return_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' notitle
set title 'evaluation distance_m'
set xlabel 'env steps (millions)'
plot 'curves/eval_distance_m_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/eval_distance_m_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'curves/eval_distance_m_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'curves/eval_distance_m_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'curves/eval_distance_m_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/eval_distance_m_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'curves/eval_distance_m_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'curves/eval_distance_m_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' notitle
set title 'evaluation speed_mps'
set xlabel 'env steps (millions)'
plot 'curves/eval_speed_mps_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/eval_speed_mps_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'curves/eval_speed_mps_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'curves/eval_speed_mps_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'curves/eval_speed_mps_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/eval_speed_mps_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'curves/eval_speed_mps_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'curves/eval_speed_mps_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' notitle
set title 'training return against wall-clock time (one core per run)'
set xlabel 'minutes'
plot 'curves/return_masa.dat' using ($2/60):4:5 with filledcurves lc rgb '#d62728' notitle, 'curves/return_masa.dat' using ($2/60):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'curves/return_sa.dat' using ($2/60):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'curves/return_sa.dat' using ($2/60):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'curves/return_sasa.dat' using ($2/60):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'curves/return_sasa.dat' using ($2/60):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'curves/return_ma.dat' using ($2/60):4:5 with filledcurves lc rgb '#9467bd' notitle, 'curves/return_ma.dat' using ($2/60):3 with lines lw 2 lc rgb '#9467bd' notitle
unset multiplot
set output
system('mv -f compare.png.tmp compare.png')
