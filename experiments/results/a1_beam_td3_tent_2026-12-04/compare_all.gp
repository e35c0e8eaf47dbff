# Every task of the grid. Redraw here with: gnuplot compare_all.gp
set terminal pngcairo size 2100,450 font ',10'
set output 'compare_all.png.tmp'
set termoption noenhanced
set style fill transparent solid 0.2 noborder
set grid
set key bottom right
set multiplot layout 1,3 title 'median and 25-75% over seeds'
set title 'a1_beam: training return'
set xlabel 'env steps (millions)'
plot 'a1_beam/curves/return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'a1_beam/curves/return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' title 'masa'
set title 'a1_beam: evaluation return (policy mean)'
plot 'a1_beam/curves/eval_return_masa.dat' using ($1/1e6):4:5 with filledcurves lc rgb '#d62728' notitle, 'a1_beam/curves/eval_return_masa.dat' using ($1/1e6):3 with lines lw 2 lc rgb '#d62728' notitle
set title 'a1_beam: training return'
set xlabel 'minutes'
plot 'a1_beam/curves/return_masa.dat' using ($2/60):4:5 with filledcurves lc rgb '#d62728' notitle, 'a1_beam/curves/return_masa.dat' using ($2/60):3 with lines lw 2 lc rgb '#d62728' notitle
unset multiplot
set output
system('mv -f compare_all.png.tmp compare_all.png')
