# gnuplot windows.gp (after windows.py): the anchor-ball fork against its control, in windows of 100
# updates after the fork point (update 2836 of the shipped run).
set terminal pngcairo size 1200,450 font ',11'
set output 'windows.png'
set datafile separator ','
set key top left
set grid
set multiplot layout 1,2 title 'Humanoid Dribbling from update 2836: the ball as the turn anchor against the same run without it'
set xlabel 'update (window of 100, centre)'
set ylabel 'training episode length (steps)'
plot 'windows.csv' every ::1 using (($1+$2)/2):3 with linespoints lw 2 title 'route\_anchor: ball', \
     '' every ::1 using (($1+$2)/2):7 with linespoints lw 2 title 'control: torso (as shipped)'
set ylabel 'evaluation: ball along the route (m, policy mean)'
plot 'windows.csv' every ::1 using (($1+$2)/2):5 with linespoints lw 2 title 'route\_anchor: ball', \
     '' every ::1 using (($1+$2)/2):9 with linespoints lw 2 title 'control: torso (as shipped)'
unset multiplot
