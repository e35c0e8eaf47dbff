# Every task of the grid. Redraw here with: gnuplot compare_all.gp
set terminal pngcairo size 2100,450 font ',10'
set output 'compare_all.png.tmp'
set termoption noenhanced
set style fill transparent solid 0.2 noborder
set grid
set key bottom right
set multiplot layout 1,3 title 'median and 25-75% over seeds'
set title 'ant_acrobatic: training return'
set xlabel 'env steps (millions)'
plot 'ant_acrobatic/curves/return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'ant_acrobatic/curves/return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' title 'sasa'
set title 'ant_acrobatic: evaluation return (policy mean)'
plot 'ant_acrobatic/curves/eval_return_sasa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'ant_acrobatic/curves/eval_return_sasa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#2ca02c' notitle
set title 'ant_acrobatic: training return'
set xlabel 'minutes'
plot 'ant_acrobatic/curves/return_sasa.dat' using ($2/60):4:5 with filledcurves lc rgb '#2ca02c' notitle, 'ant_acrobatic/curves/return_sasa.dat' using ($2/60):3 with lines lw 2 lc rgb '#2ca02c' notitle
unset multiplot
set output
system('mv -f compare_all.png.tmp compare_all.png')
