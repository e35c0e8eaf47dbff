# Learning curves of a masa run, drawn from metrics.csv (written by masa_learner).
# Re-render inside the run directory with: gnuplot learning_curve.gp
set datafile separator ","
set terminal pngcairo size 1500,900 font ",10"
set output "learning_curve.png.tmp"
set termoption noenhanced  # task and term names have underscores, not subscripts
set multiplot layout 2,3 title "humanoid_tightrope / sa (off-policy)"
set grid
# Legends under their panels, clear of the data.
set key below horizontal
set xlabel "env steps (millions)"
set style data linespoints
set pointsize 0.4
# Updates in which no episode ended have no return: the CSV says nan there.
set title "mean episode return"
plot "< xz -dc metrics.csv.xz" using (column("env_steps")/1e6):"return" pt 7 lw 2 title "return (training)", \
     "" using (column("env_steps")/1e6):"eval_return" with points pt 5 ps 0.9 title "return (policy mean)"
set title "mean episode length"
plot "< xz -dc metrics.csv.xz" using (column("env_steps")/1e6):"length" pt 7 title "length"
set title "reward terms (mean per episode)"
set key font ",8"
plot for [t in "velocity alive up heading action energy lateral termination"] "< xz -dc metrics.csv.xz" using (column("env_steps")/1e6):(column("term_".t)) pt 7 title t
set key font ",10"
set title "losses"
plot "< xz -dc metrics.csv.xz" using (column("env_steps")/1e6):"actor_loss" pt 7 title "actor", \
     "" using (column("env_steps")/1e6):"critic_loss" pt 7 title "critic"
set title "policy entropy and twin-Q loss"
plot "< xz -dc metrics.csv.xz" using (column("env_steps")/1e6):"entropy" pt 7 title "entropy (SAC)", \
     "" using (column("env_steps")/1e6):"critic_loss" pt 7 title "twin-Q loss"
set title "throughput"
plot "< xz -dc metrics.csv.xz" using (column("env_steps")/1e6):"fps" pt 7 title "env steps / s"
unset multiplot
set output
# Renamed only when complete, so a viewer never sees half a picture.
system("mv -f learning_curve.png.tmp learning_curve.png")
