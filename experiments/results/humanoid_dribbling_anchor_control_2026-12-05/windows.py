#!/usr/bin/env python3
"""Two forks of one run side by side, window by window after the fork point (standard library only).

  windows.py [--csv OUT.csv] FORK_POINT WIDTH LABEL=metrics.csv LABEL=metrics.csv ...

For each window of WIDTH updates after FORK_POINT: every run's mean training episode length and
return, and the mean of its evaluations in the window (the policy mean's route_m and length, where
the run evaluated). Only updates every run reached are compared. --csv writes the table for a plot
(windows.gp draws windows.csv).
"""
import csv
import sys


def load(path):
    with open(path) as f:
        return {int(r["update"]): r for r in csv.DictReader(f)}


def mean(rows, key):
    xs = [float(r[key]) for r in rows if r.get(key) not in (None, "", "nan")]
    return sum(xs) / len(xs) if xs else float("nan")


def main():
    args = sys.argv[1:]
    csv_out = None
    if args[:1] == ["--csv"] and len(args) > 1:
        csv_out, args = args[1], args[2:]
    if len(args) < 3:
        sys.exit(__doc__)
    fork, width = int(args[0]), int(args[1])
    runs = [(a.split("=", 1)[0], load(a.split("=", 1)[1])) for a in args[2:]]
    last = min(max(r) for _, r in runs)
    cols = ["length", "return", "eval_route_m", "eval_length"]
    out = []
    print("updates".ljust(12) + "".join(f"{l}:{c}".rjust(24) for l, _ in runs for c in cols))
    lo = fork + 1
    while lo + width - 1 <= last:
        hi = lo + width - 1
        row = {"first": lo, "last": hi}
        line = f"{lo}-{hi}".ljust(12)
        for label, r in runs:
            w = [r[u] for u in range(lo, hi + 1) if u in r]
            for c in cols:
                row[f"{label}_{c}"] = mean(w, c)
                line += f"{row[f'{label}_{c}']:24.2f}"
        print(line)
        out.append(row)
        lo += width
    if csv_out:
        with open(csv_out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(out[0]) if out else ["first", "last"])
            w.writeheader()
            w.writerows(out)


if __name__ == "__main__":
    main()
