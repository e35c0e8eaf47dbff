# Every task of the grid. Redraw here with: gnuplot compare_all.gp
set terminal pngcairo size 2100,450 font ',10'
set output 'compare_all.png.tmp'
set termoption noenhanced
set style fill transparent solid 0.2 noborder
set grid
set key bottom right
set multiplot layout 1,3 title 'median and 25-75% over seeds'
set title 'trifinger_lift: training return'
set xlabel 'env steps (millions)'
plot 'trifinger_lift/curves/return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'trifinger_lift/curves/return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' title 'masa', \
     'trifinger_lift/curves/return_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'trifinger_lift/curves/return_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' title 'sa', \
     'trifinger_lift/curves/return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'trifinger_lift/curves/return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' title 'sasa', \
     'trifinger_lift/curves/return_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'trifinger_lift/curves/return_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' title 'ma'
set title 'trifinger_lift: evaluation return (policy mean)'
plot 'trifinger_lift/curves/eval_return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'trifinger_lift/curves/eval_return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'trifinger_lift/curves/eval_return_sa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'trifinger_lift/curves/eval_return_sa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'trifinger_lift/curves/eval_return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'trifinger_lift/curves/eval_return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'trifinger_lift/curves/eval_return_ma.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#9467bd' notitle, 'trifinger_lift/curves/eval_return_ma.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#9467bd' notitle
set title 'trifinger_lift: training return'
set xlabel 'minutes'
plot 'trifinger_lift/curves/return_masa.dat' using ($2/60):4:5 with filledcurves lc rgb '#d62728' notitle, 'trifinger_lift/curves/return_masa.dat' using ($2/60):3 with lines lw 2 lc rgb '#d62728' notitle, \
     'trifinger_lift/curves/return_sa.dat' using ($2/60):4:5 with filledcurves lc rgb '#1f77b4' notitle, 'trifinger_lift/curves/return_sa.dat' using ($2/60):3 with lines lw 2 lc rgb '#1f77b4' notitle, \
     'trifinger_lift/curves/return_sasa.dat' using ($2/60):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'trifinger_lift/curves/return_sasa.dat' using ($2/60):3 with lines lw 2 lc rgb '#2ca02c' notitle, \
     'trifinger_lift/curves/return_ma.dat' using ($2/60):4:5 with filledcurves lc rgb '#9467bd' notitle, 'trifinger_lift/curves/return_ma.dat' using ($2/60):3 with lines lw 2 lc rgb '#9467bd' notitle
unset multiplot
set output
system('mv -f compare_all.png.tmp compare_all.png')
