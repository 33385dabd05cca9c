#!/usr/bin/env python3
"""Spheroid spreading on a ligand-coated substrate (seed 000, checkpoint 2).

For each cell count N, builds a spheroid of N shell cells on a flat substrate
of fixed ligand sites (`cellmd build cells --layout spheroid --count N
--substrate flat`, lowered so that the substrate lies at z = 0), runs
inputs/spheroid_spreading.in (20 000 steps, a thermo row every 2000; with
--rest, up to --steps, stopping once A changed by less than that fraction
over a window of 4000 steps) and reads
its thermo file: the spheroid's radius R = √(A0/π) from the top-down
silhouette (the convex hull of the nodes projected on xy) at the start, and
A/A0 at the end, A the mean of the last three rows (the silhouette fluctuates
by a few % as cells reshape), with its drift from the three rows before (how
far from rest the run ended). The same spheroid without clutch bonds
(`adhesion=0`) is the control; cells are R = 8 µm, level-1 shells. Fits A/A0 = a + b/R + c/R² by least squares
and compares with the PI's MCF7 law (a = −0.33, b = 188.7 µm, c = −2655 µm²,
R = 31–78 µm, r² = 0.98). Writes OUT/spheroid_spreading.csv and
OUT/summary.txt; plot.py draws OUT/spheroid_spreading.png. Needs numpy
(`bash scripts/reference-venv` prints the reference venv).

    python3 studies/spheroid_spreading/sweep.py --cellmd target/release/cellmd --out out/spheroid_spreading
    python3 studies/spheroid_spreading/plot.py --out out/spheroid_spreading
"""

import argparse
import csv
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from cellmd_run import run_command, run_deck, thermo_rows  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DECK = ROOT / "inputs" / "spheroid_spreading.in"
# The PI's MCF7 spheroids (seed 000): A/A0 = a + b/R + c/R², R in µm.
PI = {"a": -0.33, "b": 188.7, "c": -2655.0, "r_min": 31.0, "r_max": 78.0, "r2": 0.98}
CELL_RADIUS = 8.0
# Thermo rows (every 2000 steps) averaged for the equilibrium A.
TAIL = 3


def spread(cellmd, out, count, adhesion, seed, reuse, steps, rest):
    d = out / f"n{count}_adh{adhesion:g}_s{seed}"
    d.mkdir(parents=True, exist_ok=True)
    csv_path = d / "spheroid_spreading.thermo.csv"
    if not (reuse and csv_path.exists()):
        top = d / "spheroid.top"
        extent = CELL_RADIUS * (4 + 3 * count ** (1 / 3))
        build = [cellmd, "build", "cells", "--layout", "spheroid", "--count", count, "--radius", CELL_RADIUS, "--level", 1, "--gap", 0.2,
                 "--spheroid-radius", 200, "--substrate", "flat", "--substrate-spacing", 2, "--substrate-gap", 0.5,
                 "--substrate-extent", extent, "--box", extent + 10, "--seed", seed, "-o", top]
        # Built around z = 0 first; then lowered so that the substrate lies at z = 0, the deck's dish.
        floor = float(run_command(build).split("touching z = ")[1].split()[0])
        run_command(build + ["--centre", 0, 0, -floor])
        wall = run_deck(cellmd, DECK, d, {"topology": top, "adhesion": adhesion, "seed": seed, "steps": steps, "rest": rest})
        (d / "runtime_s.txt").write_text(f"{wall:.1f}\n")
    rows = thermo_rows(csv_path)
    area = np.array([r["hullarea/cells"] for r in rows])
    # The silhouette fluctuates by a few % as cells reshape: the equilibrium A is
    # the mean of the last TAIL rows, its drift the change from the TAIL rows before.
    late, earlier = area[-TAIL:].mean(), area[-2 * TAIL:-TAIL].mean()
    runtime = d / "runtime_s.txt"
    return {"count": count, "adhesion": adhesion, "seed": seed, "R": float(np.sqrt(area[0] / np.pi)),
            "A_over_A0": float(late / area[0]), "drift": float(late / earlier - 1), "steps": int(rows[-1]["step"]), "time": rows[-1]["time"],
            "clutches": int(rows[-1]["nbound/clutch"]), "runtime_s": float(runtime.read_text()) if runtime.exists() else float("nan")}


def fit(R, y):
    """Least squares y = a + b/R + c/R²: (a, b, c), r²."""
    X = np.column_stack([np.ones_like(R), 1 / R, 1 / R**2])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    residual = y - X @ coef
    return coef, 1 - residual @ residual / ((y - y.mean()) @ (y - y.mean()))


def main():
    a = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--cellmd", default=str(ROOT / "target" / "release" / "cellmd"))
    a.add_argument("--out", default=str(ROOT / "out" / "spheroid_spreading"))
    a.add_argument("--counts", type=int, nargs="+", default=[1, 2, 3, 4, 6, 9, 13])
    a.add_argument("--control-counts", type=int, nargs="+", default=[1, 4, 13], help="cell counts also run without clutches")
    a.add_argument("--seeds", type=int, default=1)
    a.add_argument("--workers", type=int, default=os.cpu_count())
    a.add_argument("--reuse", action="store_true", help="read the runs already in OUT instead of running them again")
    a.add_argument("--steps", type=int, default=20000, help="steps per run (at most, with --rest)")
    a.add_argument("--rest", type=float, default=0.0, help="stop a run once |ΔA|/A over 4000 steps is below this (0: never)")
    o = a.parse_args()
    out = Path(o.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(n, adh, s) for n in o.counts for adh in (1, 0) for s in range(1, o.seeds + 1) if adh or n in o.control_counts]
    jobs.sort(key=lambda j: -j[0])
    with ThreadPoolExecutor(o.workers) as pool:
        rows = list(pool.map(lambda j: spread(o.cellmd, out, *j, o.reuse, o.steps, o.rest), jobs))
    rows.sort(key=lambda r: (r["count"], -r["adhesion"], r["seed"]))
    with open(out / "spheroid_spreading.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [f"{'N':>4} {'adh':>3} {'seed':>4} {'R/µm':>7} {'A/A0':>7} {'drift':>8} {'steps':>7} {'t/s':>7} {'clutches':>8} {'wall/s':>7}"]
    lines += [f"{r['count']:>4} {r['adhesion']:>3g} {r['seed']:>4} {r['R']:>7.2f} {r['A_over_A0']:>7.3f} {r['drift']:>+8.3f} "
              f"{r['steps']:>7} {r['time']:>7.1f} {r['clutches']:>8} {r['runtime_s']:>7.1f}" for r in rows]
    adhered = [r for r in rows if r["adhesion"] == 1]
    R = np.array([r["R"] for r in adhered])
    y = np.array([r["A_over_A0"] for r in adhered])
    (fa, fb, fc), r2 = fit(R, y)
    pi = PI["a"] + PI["b"] / R + PI["c"] / R**2
    lines.append(f"fit A/A0 = a + b/R + c/R²: a = {fa:.3f}, b = {fb:.2f} µm, c = {fc:.1f} µm², r² = {r2:.3f} ({len(R)} points)")
    lines.append(f"PI (MCF7, R = {PI['r_min']:g}–{PI['r_max']:g} µm): a = {PI['a']}, b = {PI['b']} µm, c = {PI['c']} µm², r² = {PI['r2']}")
    lines.append("PI law at the model's R: " + ", ".join(f"{r:.1f} µm → {p:.2f}" for r, p in zip(R, pi)))
    control = [r["A_over_A0"] for r in rows if r["adhesion"] == 0]
    lines.append(f"control without clutches: A/A0 {min(control):.3f} … {max(control):.3f}")
    text = "\n".join(lines)
    print(text)
    (out / "summary.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
