#!/usr/bin/env python3
# The evaluation table of an off-policy run: every 100th round, the last, and the last ten evaluations.
#   python3 table.py metrics.csv
import csv, sys
r=list(csv.DictReader(open(sys.argv[1])))
rows=[x for x in r if x['eval_return'] not in ('','nan')]
print('| round | env steps | wall (min) | eval return | eval length | rope walked | speed |')
print('|---|---|---|---|---|---|---|')
for x in rows:
    u=int(x['update'])
    if u%100==0 or x is rows[-1]:
        print(f"| {u} | {int(x['env_steps'])/1e6:.2f}M | {float(x['wall_time_s'])/60:.0f} | {float(x['eval_return']):.1f} | {float(x['eval_length']):.1f} | {float(x['eval_distance_m']):.2f} m | {float(x['eval_speed_mps']):.2f} m/s |")
# best eval and the means of the last 10 evaluations
last=rows[-10:]
print('last 10 evals: length %.1f, distance %.2f m'%(sum(float(x['eval_length']) for x in last)/len(last), sum(float(x['eval_distance_m']) for x in last)/len(last)))
b=max(rows,key=lambda x: float(x['eval_length']))
print('longest eval: round', b['update'], b['eval_length'], b['eval_distance_m'])
