set terminal pngcairo size 1200,450 font ",10"
set output "forecast.png"
set termoption noenhanced
set multiplot layout 1,2 title "TriFinger Lift (MASA recipe, one seed): evaluation of the policy mean, and the success criterion"
set xlabel "env steps (millions)"
set key top right box opaque
set grid
set title "final position error"
set ylabel "cm"
set yrange [0:*]
plot "forecast.dat" using 1:2 with linespoints pt 7 lw 2 title "20 episodes", \
     [4.0:12.288] 100*(0.040984806063636366+-0.0004803056751598013*x) with lines dt 2 lw 2 title "fit from 4.0M", \
     2 with lines lw 2 lc rgb "#2ca02c" title "success: 2 cm"
set title "final orientation error"
set ylabel "rad"
set yrange [0:3.2]
plot "forecast.dat" using 1:3 with linespoints pt 7 lw 2 title "20 episodes", \
     [4.0:12.288] 1.9605959290909092+-0.002635497713955972*x with lines dt 2 lw 2 title "fit from 4.0M", \
     2.207416099162478 with lines lw 2 lc rgb "#7f7f7f" title "chance (random goal)", \
     0.4 with lines lw 2 lc rgb "#2ca02c" title "success: 0.4 rad"
unset multiplot
