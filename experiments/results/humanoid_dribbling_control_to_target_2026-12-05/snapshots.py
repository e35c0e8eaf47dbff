#!/usr/bin/env python3
"""Summarizes the checkpoint evaluations in evals/ (masa_eval --csv, one file per checkpoint and seed set).

  ./snapshots.py [--csv snapshots.csv]     a Markdown table on stdout; --csv also writes the numbers
Per file: episodes, the ball's mean route (m), episodes with the ball 10 m or more along the route
(the issue's measure), episodes to the time limit (1000 steps) and the mean length.
"""
import argparse, csv, glob, os, re, statistics

ap = argparse.ArgumentParser()
ap.add_argument('--csv', help='also write the table as CSV here')
args = ap.parse_args()
here = os.path.dirname(os.path.abspath(__file__))
rows = []
for path in glob.glob(os.path.join(here, 'evals', 'u*.eval*.csv')):
    m = re.match(r'u(\d+)\.eval(\d+)(?:_seed(\d+))?\.csv$', os.path.basename(path))
    if not m:
        raise SystemExit(f'snapshots.py: unexpected file name {path}')
    eps = list(csv.DictReader(open(path)))
    route = [float(e['route_m']) for e in eps]
    length = [float(e['length']) for e in eps]
    rows.append(dict(update=int(m[1]), seeds=f"{m[3] or 0}..{int(m[3] or 0) + len(eps) - 1}",
                     episodes=len(eps), route_m=round(statistics.mean(route), 2),
                     ten_m=sum(r >= 10 for r in route), time_limit=sum(l >= 1000 for l in length),
                     length=round(statistics.mean(length), 1)))
rows.sort(key=lambda r: (r['episodes'], r['update']))
print('| update | seeds | episodes | ball along the route | 10 m or more | to the time limit | length (steps) |')
print('|---|---|---|---|---|---|---|')
for r in rows:
    print(f"| {r['update']} | {r['seeds']} | {r['episodes']} | {r['route_m']:.2f} m | {r['ten_m']} | {r['time_limit']} | {r['length']:.0f} |")
if args.csv:
    with open(args.csv, 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
