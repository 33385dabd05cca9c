#!/usr/bin/env python3
"""Tissue fracture phase diagram (seed 001): force gradient × threshold strain.

Runs inputs/tissue_fracture.in once per point with `cellmd run` (the point's
force field is forcefields/tissue_fracture.ff with its threshold strain,
binding rate and maturation time replaced), reads the last thermo row of
each run (the fracture/junction/… columns) and writes OUT/phase.csv; then
plot.py draws OUT/phase.png. Not part of CI (36 runs of a 160-cell sheet).

    python3 studies/tissue_fracture/sweep.py --cellmd target/release/cellmd --out out/tissue_fracture
"""

import argparse
import csv
import os
import re
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies"))
from cellmd_run import run_deck, thermo_rows  # noqa: E402

DECK = ROOT / "inputs" / "tissue_fracture.in"
FF = ROOT / "forcefields" / "tissue_fracture.ff"
LABELS = {0: "elastic", 1: "ductile", 2: "brittle"}
QUANTITIES = ["broken", "rearranged", "ratio", "crack", "pieces", "label"]


CELL_SIZE = 3.0  # µm, the topology's cell spacing and the junction r0
SPREAD = 0.5  # the force field's threshold spread


def forcefield(strain, k_on, tau):
    """The study's force field with the point's values (each must occur once):
    capture follows the lowest threshold, D·(1 + (1 − spread/2)·strain)."""
    text = FF.read_text()
    capture = CELL_SIZE * (1 + (1 - SPREAD / 2) * strain)
    for key, value in (("strain", strain), ("k_on", k_on), ("tau", tau), ("capture", round(capture, 6))):
        text, n = re.subn(rf"(?<=[^#\w]{key} )[0-9.eE+-]+", repr(value), text)
        if n != 1:
            sys.exit(f"{FF}: expected one `{key} VALUE` outside comments, found {n}")
    return text


def run_point(cellmd, out, g, strain, k_on, tau, ramp, steps):
    name = f"g{g:g}_s{strain:g}"
    point = out / name
    point.mkdir(parents=True, exist_ok=True)
    ff = point / "tissue_fracture.ff"
    ff.write_text(forcefield(strain, k_on, tau))
    variables = {"g": g, "tau": tau, "ramp": ramp, "steps": steps, "ff": ff, "name": name}
    wall = run_deck(cellmd, DECK, point, variables)
    last = thermo_rows(point / f"{name}.thermo.csv")[-1]
    row = {"g": g, "strain": strain, "k_on": k_on, "tau": tau, "ramp": ramp, "time": float(last["time"])}
    for q in QUANTITIES:
        row[q] = float(last[f"fracture/junction/{q}"])
    row["breaks"] = int(last["breaks"])
    row["forms"] = int(last["forms"])
    row["phase"] = LABELS[int(row["label"])]
    row["wall_s"] = round(wall, 2)
    return row


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cellmd", default=str(ROOT / "target" / "debug" / "cellmd"))
    p.add_argument("--out", default=str(ROOT / "out" / "tissue_fracture"))
    p.add_argument("--gradients", default="0.3,0.45,0.6,0.8,1.0,1.2", help="pN/µm")
    p.add_argument("--strains", default="0.2,0.4,0.5,0.6,0.7,0.8,0.9")
    p.add_argument("--k-on", type=float, default=20.0, help="1/s, binding rate within capture")
    p.add_argument("--tau", type=float, default=0.5, help="s, maturation time")
    p.add_argument("--ramp", type=float, default=0.0, help="s: 0 steady pulling, else the pull grows over this time")
    p.add_argument("--steps", type=int, default=3000, help="pulling steps (dt = 0.01 s)")
    p.add_argument("--workers", type=int, default=os.cpu_count())
    a = p.parse_args()
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    points = [(float(g), float(s)) for s in a.strains.split(",") for g in a.gradients.split(",")]
    start = time.monotonic()
    with ThreadPoolExecutor(a.workers) as pool:
        rows = list(pool.map(lambda gs: run_point(a.cellmd, out, gs[0], gs[1], a.k_on, a.tau, a.ramp, a.steps), points))
    with open(out / "phase.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"{len(rows)} points in {time.monotonic() - start:.0f} s -> {out / 'phase.csv'}")
    for r in rows:
        print(f"g {r['g']:6g}  strain {r['strain']:5g}  {r['phase']:8s} broken {r['broken']:4.0f}  rearranged {r['rearranged']:4.0f}"
              f"  ratio {r['ratio']:5.2f}  crack {r['crack']:3.0f}  pieces {r['pieces']:2.0f}")


if __name__ == "__main__":
    main()
