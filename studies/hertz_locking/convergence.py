"""Hertz indentation of a graded quarter block at ν → 0.5: plain linear
tetrahedra (`neo_hookean`) against average-nodal-pressure tetrahedra
(`neo_hookean_anp`, Bonet & Burton 1998), on three refinements of the mesh
(issue #46). Table in docs/src/user-guide/solids.md.

For each mesh (`cellmd build block --quarter`, half-width and depth L), law
and Poisson's ratio ν: inputs/hertz_block.in (a rigid sphere R = 5 µm, E =
1 kPa, 5 stages up to δ = 0.1·R, each relaxed by 25 implicit steps) and
F/Hertz − 1 at each stage, F four times the quarter's load on the indenter,
Hertz F = (4/3)·E/(1 − ν²)·√R·δ^{3/2}; the relative load change over each
stage's last step says it is relaxed.

    python3 studies/hertz_locking/convergence.py [--laws neo_hookean_anp,neo_hookean]
        [--nu 0.3,0.45,0.49,0.499] [--meshes L:cells:spacing:core,…] [--jobs 2]

Writes results/convergence.csv and prints the table. Units: µm, s, pN.
"""

import argparse
import concurrent.futures
import csv
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "studies"))
from cellmd_run import run_command, run_deck  # noqa: E402

CELLMD = ROOT / "target" / "release" / "cellmd"
DECK = ROOT / "inputs" / "hertz_block.in"
RADIUS, YOUNG, STAGES, STEPS = 5.0, 1000.0, 5, 25
# The refinements: half-width L (µm), cells, spacing at the contact (µm), uniform core cells.
MESHES = "50:10:0.35:4,50:12:0.29:5,50:14:0.25:6"
FF = """particle node drag 1
particle node_x drag 1
particle node_y drag 1
particle node_xy drag 1
particle node_base drag 1
tetra solid {law} e {e} nu {nu}
"""


def hertz(delta, nu):
    return 4.0 / 3.0 * YOUNG / (1.0 - nu * nu) * math.sqrt(RADIUS) * delta**1.5


def stage_ends(path):
    """The indenter's load (thermo `fz/tip`) at the end of each stage and
    one step before (the deck's `thermo_every 1`: every step, a stage's
    first row repeating the previous stage's last)."""
    with open(path, newline="") as f:
        rows = [(int(r[0]), float(r[1])) for r in list(csv.reader(f))[1:]]
    ends = [k for k in range(1, len(rows)) if rows[k][0] % STEPS == 0 and rows[k][0] > 0 and rows[k - 1][0] == rows[k][0] - 1]
    return [rows[k][1] for k in ends], [rows[k - 1][1] for k in ends]


def one(job):
    (half_width, cells, spacing, core), law, nu = job
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        top, ff = tmp / "block.top", tmp / "block.ff"
        run_command([CELLMD, "build", "block", "--quarter", "--half-width", half_width, "--cells", cells,
                     "--spacing", spacing, "--core-cells", core, "-o", top])
        ff.write_text(FF.format(law=law, e=YOUNG, nu=nu))
        variables = {"topology": top, "forcefield": ff, "extent": half_width, "thermo_every": 1}
        seconds = run_deck(CELLMD, DECK, tmp, variables)
        after, before = stage_ends(tmp / "hertz_block.thermo.csv")
    assert len(after) == STAGES, after
    loads = [-4.0 * f for f in after]
    excess = [F / hertz(RADIUS * 0.1 * (k + 1) / STAGES, float(nu)) - 1.0 for k, F in enumerate(loads)]
    drift = max(abs((a - b) / a) for a, b in zip(after, before))
    return {"L": half_width, "cells": cells, "spacing": spacing, "core": core, "nodes": (int(cells) + 1) ** 3,
            "law": law, "nu": nu, "excess": excess, "drift": drift, "seconds": seconds}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--laws", default="neo_hookean_anp,neo_hookean")
    parser.add_argument("--nu", default="0.3,0.45,0.49,0.499")
    parser.add_argument("--meshes", default=MESHES)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", default=str(HERE / "results" / "convergence.csv"))
    args = parser.parse_args()
    meshes = [tuple(m.split(":")) for m in args.meshes.split(",")]
    jobs = [(m, law, nu) for law in args.laws.split(",") for nu in args.nu.split(",") for m in meshes]
    os.makedirs(Path(args.out).parent, exist_ok=True)
    print("| law | ν | mesh (L:cells:spacing:core, nodes) | F/Hertz − 1 at δ/R = 0.02, 0.04, 0.06, 0.08, 0.10 | drift | s |")
    print("|---|---|---|---|---|---|", flush=True)
    with open(args.out, "w", newline="") as f, concurrent.futures.ProcessPoolExecutor(args.jobs) as pool:
        w = csv.writer(f)
        w.writerow(["law", "nu", "L", "cells", "spacing", "core", "nodes"] +
                   [f"excess_{0.1 * (k + 1) / STAGES:.2f}" for k in range(STAGES)] + ["drift", "seconds"])
        for r in pool.map(one, jobs):
            w.writerow([r["law"], r["nu"], r["L"], r["cells"], r["spacing"], r["core"], r["nodes"]] +
                       [f"{e:+.4f}" for e in r["excess"]] + [f"{r['drift']:.1e}", f"{r['seconds']:.0f}"])
            f.flush()
            mesh = f"{r['L']}:{r['cells']}:{r['spacing']}:{r['core']}, {r['nodes']}"
            excess = ", ".join(f"{100 * e:+.1f} %" for e in r["excess"])
            print(f"| {r['law']} | {r['nu']} | {mesh} | {excess} | {r['drift']:.0e} | {r['seconds']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
