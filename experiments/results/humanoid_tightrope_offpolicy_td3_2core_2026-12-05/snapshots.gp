# gnuplot snapshots.gp -> snapshots.png: each 100th round's policy mean over 20 episodes (snapshots.csv)
set terminal pngcairo size 1000,700 font ",11"
set output "snapshots.png"
set datafile separator ","
set multiplot layout 2,1 title "Humanoid Tightrope, TD3-MASA (tilt 30 deg), both cores of a 2-vCPU VM, seed 0"
set grid
set xrange [0:190]
set arrow 1 from 180, graph 0 to 180, graph 1 nohead lc rgb "red" dt 2 lw 1.5
set key bottom right
set ylabel "episodes to the time limit (of 20)"
set yrange [0:20.5]
plot "snapshots.csv" skip 1 using 3:4 with linespoints pt 7 lw 2 title "to the time limit", \
     16 with lines lc rgb "red" dt 2 title "target: 16 of 20 within 3 hours (red line)"
set key top left
set xlabel "wall time (min)"
set ylabel "rope walked, mean (m)"
set yrange [0:*]
plot "metrics.csv" skip 1 using ($3 / 60):($31 == $31 ? $31 : 1/0) with points pt 7 ps 0.3 lc rgb "gray" title "the run's own evaluation (8 episodes, every 10 rounds)", \
     "snapshots.csv" skip 1 using 3:6 with linespoints pt 7 lw 2 title "rope walked in the 1000-step episode (20 episodes)", \
     "snapshots.csv" skip 1 using 3:($7 * 10) with linespoints pt 6 dt 2 title "speed x 10 (m/s)"
unset multiplot
