# Every task of the grid. Redraw here with: gnuplot compare_all.gp
set terminal pngcairo size 2100,450 font ',10'
set output 'compare_all.png.tmp'
set termoption noenhanced
set style fill transparent solid 0.2 noborder
set grid
set key bottom right
set multiplot layout 1,3 title 'median and 25-75% over seeds'
set title 'humanoid_tightrope: training return'
set xlabel 'env steps (millions)'
plot 'humanoid_tightrope/curves/return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'humanoid_tightrope/curves/return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' title 'masa', \
     'humanoid_tightrope/curves/return_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'humanoid_tightrope/curves/return_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' title 'sa', \
     'humanoid_tightrope/curves/return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'humanoid_tightrope/curves/return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' title 'sasa', \
     'humanoid_tightrope/curves/return_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'humanoid_tightrope/curves/return_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' title 'ma'
set title 'humanoid_tightrope: evaluation return (policy mean)'
plot 'humanoid_tightrope/curves/eval_return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'humanoid_tightrope/curves/eval_return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'humanoid_tightrope/curves/eval_return_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'humanoid_tightrope/curves/eval_return_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'humanoid_tightrope/curves/eval_return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'humanoid_tightrope/curves/eval_return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'humanoid_tightrope/curves/eval_return_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'humanoid_tightrope/curves/eval_return_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' notitle
set title 'humanoid_tightrope: training return'
set xlabel 'minutes'
plot 'humanoid_tightrope/curves/return_masa.dat' using ($2/60):4:5 with filledcurves lc rgb '#d62728' notitle, 'humanoid_tightrope/curves/return_masa.dat' using ($2/60):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'humanoid_tightrope/curves/return_sa.dat' using ($2/60):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'humanoid_tightrope/curves/return_sa.dat' using ($2/60):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'humanoid_tightrope/curves/return_sasa.dat' using ($2/60):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'humanoid_tightrope/curves/return_sasa.dat' using ($2/60):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'humanoid_tightrope/curves/return_ma.dat' using ($2/60):4:5 with filledcurves lc rgb '#9467bd' notitle, 'humanoid_tightrope/curves/return_ma.dat' using ($2/60):3 with lines lw 2 lc rgb '#9467bd' notitle
unset multiplot
set output
system('mv -f compare_all.png.tmp compare_all.png')
