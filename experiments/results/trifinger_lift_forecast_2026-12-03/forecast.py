#!/usr/bin/env python3
"""TriFinger Lift: what a run's evaluation curve says about the steps success would need (issue #31).

Reads a metrics.csv with eval_position_error_m and eval_orientation_error_rad, fits a straight line to
each over the steps from --from (millions) on, with a bootstrap 95% interval of the slope over the
evaluation points, and prints when each line would reach the success criterion (2 cm, 0.4 rad);
writes forecast.dat and draws forecast.png (gnuplot) with the criterion and the chance level.

  python3 forecast.py METRICS_CSV [--from 4] [--out DIR]
"""
import argparse
import csv
import math
import os
import random
import statistics
import subprocess

# The mean rotation angle between two independent uniformly random orientations (Haar measure:
# density (1 - cos t) / pi on [0, pi]): pi/2 + 2/pi. The goal is uniform on SO(3), so a policy that
# does not orient the cube sits here whatever the cube's own orientation.
CHANCE_ORIENTATION_RAD = math.pi / 2 + 2 / math.pi


def fit(points):
    xs, ys = zip(*points)
    mx, my = statistics.mean(xs), statistics.mean(ys)
    slope = sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x in xs)
    return slope, my - slope * mx


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("metrics")
    ap.add_argument("--from", dest="start", type=float, default=4.0, help="fit from these env steps (millions)")
    ap.add_argument("--out", default=".")
    ap.add_argument("--resamples", type=int, default=10000)
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.metrics)))
    ev = []
    for r in rows:
        try:
            p, o = float(r["eval_position_error_m"]), float(r["eval_orientation_error_rad"])
        except (KeyError, ValueError):
            continue
        if math.isfinite(p) and math.isfinite(o):
            ev.append((int(r["env_steps"]) / 1e6, p, o, float(r.get("eval_success", "nan"))))
    if len(ev) < 3:
        raise SystemExit(f"{a.metrics}: fewer than 3 evaluations with position and orientation errors")
    late = [e for e in ev if e[0] >= a.start]
    if len(late) < 3:
        raise SystemExit(f"fewer than 3 evaluations from {a.start}M steps on")
    rng = random.Random(0)
    print(f"{a.metrics}: {len(ev)} evaluations to {ev[-1][0]:.1f}M steps; fit over the {len(late)} from {a.start}M")
    print(f"success rate at the evaluations: {', '.join(f'{e[3]:.2f}' for e in ev)}")
    fits = {}
    for k, name, target, unit in ((1, "position error", 0.02, "m"), (2, "orientation error", 0.4, "rad")):
        pts = [(e[0], e[k]) for e in late]
        slope, icpt = fit(pts)
        boots = []
        while len(boots) < a.resamples:
            s = [rng.choice(pts) for _ in pts]
            if len({p[0] for p in s}) > 1:
                boots.append(fit(s)[0])
        boots.sort()
        lo, hi = boots[int(0.025 * len(boots))], boots[int(0.975 * len(boots)) - 1]
        mean = statistics.mean(p[1] for p in pts)
        when = (target - icpt) / slope if slope < 0 else math.inf
        reach = f"{when:.0f}M steps" if math.isfinite(when) else "never (the line does not fall)"
        verdict = ("the interval includes no progress: the curve gives no forecast"
                   if hi >= 0 else f"the slowest slope in the interval reaches it at {(target - icpt) / hi:.0f}M")
        print(f"{name}: mean {mean:.4g} {unit} from {a.start}M on; slope {slope:.3g} {unit}/M steps "
              f"[95% {lo:.3g}, {hi:.3g}]; the line reaches {target} {unit} at {reach}; {verdict}")
        fits[name] = (slope, icpt)
    print(f"chance level of the orientation error (a goal uniform on SO(3)): {CHANCE_ORIENTATION_RAD:.3f} rad")
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "forecast.dat"), "w") as f:
        f.write("# env_steps_M position_error_cm orientation_error_rad success\n")
        for e in ev:
            f.write(f"{e[0]:.4f} {100 * e[1]:.4f} {e[2]:.4f} {e[3]:.3f}\n")
    sp, ip = fits["position error"]
    so, io = fits["orientation error"]
    gp = f"""set terminal pngcairo size 1200,450 font ",10"
set output "forecast.png"
set termoption noenhanced
set multiplot layout 1,2 title "TriFinger Lift (MASA recipe, one seed): evaluation of the policy mean, and the success criterion"
set xlabel "env steps (millions)"
set key top right box opaque
set grid
set title "final position error"
set ylabel "cm"
set yrange [0:*]
plot "forecast.dat" using 1:2 with linespoints pt 7 lw 2 title "20 episodes", \\
     [{a.start}:{ev[-1][0]}] 100*({ip}+{sp}*x) with lines dt 2 lw 2 title "fit from {a.start}M", \\
     2 with lines lw 2 lc rgb "#2ca02c" title "success: 2 cm"
set title "final orientation error"
set ylabel "rad"
set yrange [0:3.2]
plot "forecast.dat" using 1:3 with linespoints pt 7 lw 2 title "20 episodes", \\
     [{a.start}:{ev[-1][0]}] {io}+{so}*x with lines dt 2 lw 2 title "fit from {a.start}M", \\
     {CHANCE_ORIENTATION_RAD} with lines lw 2 lc rgb "#7f7f7f" title "chance (random goal)", \\
     0.4 with lines lw 2 lc rgb "#2ca02c" title "success: 0.4 rad"
unset multiplot
"""
    with open(os.path.join(a.out, "forecast.gp"), "w") as f:
        f.write(gp)
    subprocess.run(["gnuplot", "forecast.gp"], cwd=a.out, check=True)
    print(f"wrote {os.path.join(a.out, 'forecast.png')}")


if __name__ == "__main__":
    main()
