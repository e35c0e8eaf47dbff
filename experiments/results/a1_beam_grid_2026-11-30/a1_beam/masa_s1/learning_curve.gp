# Learning curves of a masa run, drawn from metrics.csv (written by masa_learner).
# Re-render inside the run directory with: gnuplot learning_curve.gp
set datafile separator ","
set terminal pngcairo size 1500,900 font ",10"
set output "learning_curve.png.tmp"
set termoption noenhanced  # task and term names have underscores, not subscripts
set multiplot layout 2,3 title "a1_beam / masa"
set grid
set key top left
set xlabel "env steps"
set style data linespoints
set pointsize 0.4
# Updates in which no episode ended have no return: the CSV says nan there.
set title "mean episode return"
plot "< xz -dc metrics.csv.xz" using "env_steps":"return" pt 7 lw 2 title "return (training)", \
     "" using "env_steps":"eval_return" with points pt 5 ps 0.9 title "return (policy mean)"
set title "mean episode length and success rate"
set ytics nomirror
set y2tics
set y2range [0:1]
plot "< xz -dc metrics.csv.xz" using "env_steps":"length" pt 7 title "length", \
     "" using "env_steps":(column("success") < 0 ? NaN : column("success")) axes x1y2 pt 7 title "success"
unset y2tics
set ytics mirror
set title "reward terms (mean per episode)"
set key top left font ",8"
plot for [t in "velocity alive heading action lateral termination"] "< xz -dc metrics.csv.xz" using "env_steps":(column("term_".t)) pt 7 title t
set key top left font ",10"
set title "losses"
plot "< xz -dc metrics.csv.xz" using "env_steps":"actor_loss" pt 7 title "actor", \
     "" using "env_steps":"critic_loss" pt 7 title "critic"
set title "KL and learning rate"
set logscale y
plot "< xz -dc metrics.csv.xz" using "env_steps":"kl" pt 7 title "KL(old||new)", \
     "" using "env_steps":"lr" pt 7 title "learning rate"
unset logscale y
set title "throughput"
plot "< xz -dc metrics.csv.xz" using "env_steps":"fps" pt 7 title "env steps / s"
unset multiplot
set output
# Renamed only when complete, so a viewer never sees half a picture.
system("mv -f learning_curve.png.tmp learning_curve.png")
