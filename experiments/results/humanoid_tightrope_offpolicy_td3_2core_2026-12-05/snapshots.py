#!/usr/bin/env python3
# Each 100th round's policy over 20 episodes (seeds 0-19, the policy mean; snapshots/uN.eval20.csv,
# written by masa_eval --csv), with the round's env steps and wall time from the run's metrics.csv.
#   python3 snapshots.py metrics.csv snapshots   -> snapshots.md (the table), snapshots.csv (the figure's data)
import csv, glob, re, sys
metrics = {int(x['update']): x for x in csv.DictReader(open(sys.argv[1]))}
md = ['| round | env steps | wall (min) | to the time limit | mean length | rope walked | speed | farthest |',
      '|---|---|---|---|---|---|---|---|']
rows = []
for f in sorted(glob.glob(sys.argv[2] + '/u*.eval20.csv'), key=lambda p: int(re.findall(r'u(\d+)', p)[-1])):
    u = int(re.findall(r'u(\d+)', f)[-1])
    r = list(csv.DictReader(open(f)))
    if len(r) != 20 or u not in metrics:
        continue
    L = [int(float(x['length'])) for x in r]
    d = [float(x['distance_m']) for x in r]
    v = [float(x['speed_mps']) for x in r]
    steps, wall = int(metrics[u]['env_steps']), float(metrics[u]['wall_time_s']) / 60
    limit = sum(l >= 1000 for l in L)
    md.append(f"| {u} | {steps/1e6:.2f}M | {wall:.0f} | {limit}/20 | {sum(L)/20:.0f} | {sum(d)/20:.2f} m | {sum(v)/20:.2f} m/s | {max(d):.2f} m |")
    rows.append([u, steps, f"{wall:.1f}", limit, f"{sum(L)/20:.1f}", f"{sum(d)/20:.3f}", f"{sum(v)/20:.3f}"])
open('snapshots.md', 'w').write('\n'.join(md) + '\n')
with open('snapshots.csv', 'w', newline='') as f:
    w = csv.writer(f)
    w.writerow(['update', 'env_steps', 'wall_min', 'time_limit_of_20', 'mean_length', 'distance_m', 'speed_mps'])
    w.writerows(rows)
print('\n'.join(md))
