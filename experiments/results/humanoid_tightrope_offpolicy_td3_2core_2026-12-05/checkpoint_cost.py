#!/usr/bin/env python3
"""How much of an off-policy run's wall time its checkpoints took, from its metrics.csv.

  ./checkpoint_cost.py [metrics.csv] [checkpoint_every]
The learner writes its state (networks, optimizers and the replay buffer) after every
checkpoint_every-th round; the write lands in the next round's wall time. A checkpoint round's
excess is its time minus the median of the other rounds within 50 of it.
"""
import csv, statistics, sys

path = sys.argv[1] if len(sys.argv) > 1 else 'metrics.csv'
every = int(sys.argv[2]) if len(sys.argv) > 2 else 10
rows = list(csv.DictReader(open(path)))
wall = [(int(r['update']), float(r['wall_time_s'])) for r in rows]
dt = [(wall[i][0], wall[i][1] - wall[i - 1][1]) for i in range(1, len(wall))]
is_ckpt = lambda u: u % every == 1
total = sum(t for _, t in dt)
excess = sum(t - statistics.median([x for v, x in dt if not is_ckpt(v) and abs(v - u) < 50])
             for u, t in dt if is_ckpt(u))
print(f'rounds {wall[0][0]}-{wall[-1][0]}: {total:.0f} s, of which checkpoints {excess:.0f} s ({100 * excess / total:.0f}%)')
print('| rounds | a round after a checkpoint | any other round |')
print('|---|---|---|')
for lo in range(1, wall[-1][0], 200):
    c = [t for u, t in dt if lo <= u < lo + 200 and is_ckpt(u)]
    o = [t for u, t in dt if lo <= u < lo + 200 and not is_ckpt(u)]
    if c and o:
        print(f'| {lo}-{lo + 199} | {statistics.median(c):.1f} s | {statistics.median(o):.2f} s |')
