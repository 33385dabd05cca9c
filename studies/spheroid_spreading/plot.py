#!/usr/bin/env python3
"""Plots sweep.py's OUT/spheroid_spreading.csv: A/A0 at the end of the run against the
spheroid radius R, with the least-squares fit a + b/R + c/R² and the PI's
MCF7 law (seed 000) overlaid, and the controls without clutch bonds.
Writes OUT/spheroid_spreading.png. Needs numpy and matplotlib.

    python3 studies/spheroid_spreading/plot.py --out out/spheroid_spreading
"""

import argparse
import csv
from pathlib import Path

import numpy as np

from sweep import PI, ROOT, fit


def main():
    a = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--out", default=str(ROOT / "out" / "spheroid_spreading"))
    o = a.parse_args()
    out = Path(o.out)
    with open(out / "spheroid_spreading.csv") as f:
        rows = list(csv.DictReader(f))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for adhesion, style, label in [("1", "o", "model, clutch bonds"), ("0", "x", "model, no clutch bonds (control)")]:
        sel = [r for r in rows if r["adhesion"] == adhesion]
        R = np.array([float(r["R"]) for r in sel])
        y = np.array([float(r["A_over_A0"]) for r in sel])
        ax.plot(R, y, style, color="#c44e52" if adhesion == "1" else "#555", label=label)
        if adhesion == "1":
            (fa, fb, fc), r2 = fit(R, y)
            rr = np.linspace(R.min(), R.max(), 200)
            ax.plot(rr, fa + fb / rr + fc / rr**2, "-", color="#c44e52", lw=1,
                    label=f"fit a + b/R + c/R²: a = {fa:.2f}, b = {fb:.1f} µm, c = {fc:.0f} µm², r² = {r2:.2f}")
    rr = np.linspace(PI["r_min"], PI["r_max"], 200)
    ax.plot(rr, PI["a"] + PI["b"] / rr + PI["c"] / rr**2, "--", color="#4c72b0",
            label=f"PI MCF7 law: a = {PI['a']}, b = {PI['b']} µm, c = {PI['c']:.0f} µm² (R = 31–78 µm)")
    ax.axhline(1, color="#999", lw=0.6)
    ax.set_xlabel("spheroid radius R = √(A0/π) (µm)")
    ax.set_ylabel("A/A0 at the end of the run (top-down silhouette)")
    ax.set_title("Spheroid spreading on a ligand-coated substrate (seed 000, checkpoint 2)", fontsize=10)
    ax.legend(frameon=False, fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "spheroid_spreading.png", dpi=130)
    print(f"-> {out / 'spheroid_spreading.png'}")


if __name__ == "__main__":
    main()
