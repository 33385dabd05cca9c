#!/usr/bin/env python3
"""τ(F) table from a cellmd event log: mean lifetime per bond type.

    python3 inputs/lifetime_table.py EVENTS.csv [TIMESTEP]

A bond that breaks while step s is decided was bound through s·dt and broke
within that step, so its lifetime is estimated as (s + ½)·dt. Prints
`type,force,n,tau,stderr` (units of the run: pN, s).
"""
import csv
import math
import sys
from collections import defaultdict

path = sys.argv[1]
rows = [r for r in csv.DictReader(open(path)) if r["event"] == "break"]
if not rows:
    sys.exit("no break events")
time_key = next(k for k in rows[0] if k.startswith("time"))
force_key = next(k for k in rows[0] if k.startswith("force"))
dt = float(sys.argv[2]) if len(sys.argv) > 2 else None
groups = defaultdict(list)
for r in rows:
    t = float(r[time_key])
    if dt is not None:
        t = (int(r["step"]) + 0.5) * dt
    groups[r["type"]].append((float(r[force_key]), t))
print("type,force,n,tau,stderr")
for name, events in sorted(groups.items(), key=lambda kv: kv[1][0][0]):
    taus = [t for _, t in events]
    n = len(taus)
    mean = sum(taus) / n
    sd = math.sqrt(sum((t - mean) ** 2 for t in taus) / max(n - 1, 1))
    print(f"{name},{events[0][0]:.4g},{n},{mean:.5g},{sd / math.sqrt(n):.2g}")
