#!/usr/bin/env python3
"""Plots of studies/tensegrity_substrate/sweep.py: OUT/curvature.png (the
read-outs of Vassaux & Milan's Fig. 7 against 1/R, concave > 0) and
OUT/indentation.png (the relaxed load against the indenter's travel).

    python3 studies/tensegrity_substrate/plot.py out/tensegrity_substrate
"""

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

out = Path(sys.argv[1])
rows = list(csv.DictReader(open(out / "curvature.csv")))
x = [float(r["inverse_radius_per_um"]) for r in rows]
panels = [
    ("nucleus_volumetric_strain", "nucleus volumetric strain"),
    ("nucleus_vertical_strain", "nucleus vertical strain"),
    ("stress_fibre_force_pN", "stress-fibre tension, summed (pN)"),
    ("cortex_tension_sum_pN", "cortex-cable tension, summed (pN)"),
]
fig, axes = plt.subplots(2, 2, figsize=(9, 7))
for ax, (key, label) in zip(axes.flat, panels):
    ax.plot(x, [float(r[key]) for r in rows], "o-")
    ax.set_xlabel("1/R (1/µm; > 0 concave, < 0 convex)")
    ax.set_ylabel(label)
    ax.axvline(0, color="grey", lw=0.5)
fig.suptitle("Tensegrity cell spread to 47.15 nN, then contracted")
fig.tight_layout()
fig.savefig(out / "curvature.png", dpi=120)

rows = list(csv.DictReader(open(out / "indentation.csv")))
fig, ax = plt.subplots(figsize=(5, 4))
ax.plot([float(r["travel_um"]) for r in rows], [float(r["load_pN"]) / 1000 for r in rows], "o-")
ax.set_xlabel("indenter travel since contact (µm)")
ax.set_ylabel("load (nN)")
ax.set_title("Nano-indentation, sphere of radius 5 µm, flat substrate")
fig.tight_layout()
fig.savefig(out / "indentation.png", dpi=120)
