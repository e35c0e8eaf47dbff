# gnuplot snapshots.gp -> snapshots.png: each checkpoint's evaluation of the policy mean (snapshots.csv)
set terminal pngcairo size 900,420 font ",11"
set output "snapshots.png"
set datafile separator ","
set key outside bottom center horizontal
set grid
set xlabel "update"
set ylabel "share of episodes"
set yrange [0:1]
set xrange [3650:4850]
set title "Humanoid Dribbling, cap 1.2 / alive 2.0 run: the ball 10 m or more along the route (target: 16 of 20)"
target(x) = 0.8
plot "snapshots.csv" using 1:($3 == 20 ? $5 / 20.0 : NaN) with linespoints pt 7 lw 2 title "10 m or more, seeds 0-19", \
     "" using 1:($3 == 20 ? $6 / 20.0 : NaN) with linespoints pt 6 dt 2 title "to the time limit, seeds 0-19", \
     "" using 1:($3 == 100 ? $5 / 100.0 : NaN) with points pt 5 ps 1.6 title "10 m or more, seeds 1000-1099", \
     target(x) with lines lc rgb "red" dt 2 lw 1.5 title "target (16 of 20)"
