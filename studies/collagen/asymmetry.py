#!/usr/bin/env python3
"""Does the fibres' asymmetry drive clustering? (seed 002's claim; issue #19)

Runs inputs/collagen_two_cells.in on the two-cell network built with
`--seed` 1 … N (independent realisations), each with asymmetric fibres
(k_compression = 1 pN/µm, tension 100) and symmetric ones (100), and reads
three measures at every stage:

- `paper`: the deck's thermo column clustering/fibre/cell1/cell2, the
  paper's S_max/S_min in the band between the rings (the band follows the
  rings as they shrink);
- `band_gain`: the same profile in a frame fixed at the network as built
  (the gap between the initial rings, x within ±(D/2 − R), 21 strips over
  |y| ≤ 1.5 R): the mean of the 7 central strips (on the axis) over that of
  the 3 outermost at each end, divided by its value as built. It is 1
  when nothing moves and > 1 when fibres gather onto the axis between the
  cells, whatever the realisation's initial profile;
- `mid_half`: the paper's S_max/S_min in that fixed frame's middle half of
  the gap (x within ±(D/2 − R)/2).

Writes OUT/asymmetry.csv (one row per run and stage) and prints, for the
last stage, the mean ± standard error over the realisations of the paper
ratio's growth, the band gain and the mid-half ratio's growth, asymmetric
and symmetric, and of their paired difference. The README's table (*Collagen clustering study*) is its
output. Needs numpy (`bash scripts/reference-venv`).

A finished run leaves OUT/seedS_FIBRES/rows.json, and a second call with the
same OUT and settings reads it instead of running again, so a long study can
be stopped and resumed (or extended to more seeds). A run that cellmd stops
(a blow-up) is reported with cellmd's message, and its realisation is left
out of both columns, so the differences stay paired.

    python3 studies/collagen/asymmetry.py --cellmd target/release/cellmd --out out/collagen_asym --seeds 5 --steps 1000 --workers 2
"""

import argparse
import csv
import json
import math
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from plot import fibres_of, frames, sample

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies"))
from cellmd_run import run_command, run_deck, thermo_rows  # noqa: E402

DECK = ROOT / "inputs" / "collagen_two_cells.in"
SEPARATION, RADIUS = 600.0, 100.0  # µm, the deck's pair (the paper's clusters)
NETWORK = ["--layout", "pair", "--separation", "600", "--cell-radius", "100", "--size", "1000", "600"]
FIBRES = {"asymmetric": 1.0, "symmetric": 100.0}  # k_compression, pN/µm (k_tension 100)
STRIPS, PEAK, END = 21, 7, 3  # as the clustering column (src/measure/clustering.rs)


def profile(pos, bonds, reach):
    """Fibre length in 21 strips across |y| ≤ 1.5 R, of the part of the
    network within |x| ≤ reach (a frame fixed at the network as built)."""
    half = 1.5 * RADIUS
    pts, w = sample(pos, bonds, 0.5)
    inside = (np.abs(pts[:, 0]) <= reach) & (np.abs(pts[:, 1]) <= half)
    return np.histogram(pts[inside, 1], bins=STRIPS, range=(-half, half), weights=w[inside])[0]


def band(p):
    """The 7 central strips (on the axis) over the 3 outermost at each end."""
    middle = (STRIPS - PEAK) // 2
    return p[middle : middle + PEAK].mean() / np.r_[p[:END], p[-END:]].mean()


def paper_ratio(p):
    """S_max/S_min as the clustering column takes it (7 strips around the densest)."""
    first = min(max(int(np.argmax(p)) - PEAK // 2, 0), STRIPS - PEAK)
    return p[first : first + PEAK].mean() / np.r_[p[:END], p[-END:]].mean()


def settings(a):
    """What a finished run's rows depend on: a stored run is reused only when these match."""
    keys = ("steps", "stages", "bend", "dt", "density", "fibre_length", "node_spacing", "temperature")
    return {k: str(getattr(a, k)) for k in keys}


def run(a, seed, fibres):
    """The per-stage rows of one run (reused from rows.json when the
    settings match), or None when cellmd stopped it."""
    name = f"seed{seed}_{fibres}"
    point = Path(a.out).resolve() / name
    point.mkdir(parents=True, exist_ok=True)
    stored = point / "rows.json"
    if stored.exists():
        done = json.loads(stored.read_text())
        done["settings"].setdefault("temperature", "0.0")  # rows stored before the option existed
        if done["settings"] == settings(a):
            return done["rows"]
    try:
        rows = simulate(a, seed, fibres, name, point)
    except SystemExit as stop:  # run_command's exit: cellmd failed (a blow-up)
        print(f"{name}: stopped, left out\n{stop}", flush=True)
        return None
    stored.write_text(json.dumps({"settings": settings(a), "rows": rows}))
    return rows


def simulate(a, seed, fibres, name, point):
    top = point / "collagen.top"
    network = NETWORK + ["--density", a.density, "--fibre-length", a.fibre_length, "--node-spacing", a.node_spacing]
    run_command([a.cellmd, "build", "collagen", *network, "--seed", seed, "-o", top])
    variables = {"top": top, "kc": FIBRES[fibres], "bend": a.bend, "dt": a.dt, "steps": a.steps, "stages": a.stages, "name": name,
                 "T": a.temperature, "noise_seed": seed}
    wall = run_deck(a.cellmd, DECK, point, variables)
    paper = [r["clustering/fibre/cell1/cell2"] for r in thermo_rows(point / f"{name}.thermo.csv")]
    bonds = fibres_of(top)
    gap = SEPARATION / 2 - RADIUS
    shots = frames(point / f"{name}.xyz")  # as built, then each stage's end
    bands = [band(profile(pos, bonds, gap)) for pos in shots]
    mids = [paper_ratio(profile(pos, bonds, gap / 2)) for pos in shots]
    print(f"{name}: paper {paper[0]:.3f} -> {paper[-1]:.3f}, band gain {bands[-1] / bands[0]:.3f}, {wall:.0f} s", flush=True)
    return [
        {"seed": seed, "fibres": fibres, "stage": s, "paper": round(p, 5), "band_gain": round(b / bands[0], 5), "mid_half": round(m, 5), "wall_s": round(wall, 1)}
        for s, (p, b, m) in enumerate(zip(paper, bands, mids))
    ]


def mean_se(values):
    m = sum(values) / len(values)
    se = math.sqrt(sum((v - m) ** 2 for v in values) / (len(values) - 1) / len(values)) if len(values) > 1 else float("nan")
    return f"{m:+.3f} ± {se:.3f}"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cellmd", default=str(ROOT / "target" / "release" / "cellmd"))
    p.add_argument("--out", default=str(ROOT / "out" / "collagen_asymmetry"))
    p.add_argument("--seeds", type=int, default=5, help="network realisations (builder --seed 1 … N)")
    p.add_argument("--steps", type=int, default=1000, help="steps per stage")
    p.add_argument("--stages", type=int, default=10)
    p.add_argument("--bend", type=float, default=400, help="pN·µm, the fibres' bending K")
    p.add_argument("--dt", type=float, default=0.001, help="s, the time step (2.5e-4 for K 4000)")
    p.add_argument("--density", default="0.1")
    p.add_argument("--fibre-length", default="200")
    p.add_argument("--node-spacing", default="10")
    p.add_argument("--temperature", type=float, default=0.0, help="K, the deck's T (kT = 1.380649e-5·T pN·µm; 72 429 K: kT = 1 pN·µm)")
    p.add_argument("--workers", type=int, default=1, help="runs at a time (each cellmd run takes one thread)")
    a = p.parse_args()
    points = [(seed, fibres) for seed in range(1, a.seeds + 1) for fibres in FIBRES]
    with ThreadPoolExecutor(a.workers) as pool:
        runs = dict(zip(points, pool.map(lambda point: run(a, *point), points)))
    seeds = [s for s in range(1, a.seeds + 1) if all(runs[(s, f)] is not None for f in FIBRES)]
    if len(seeds) < a.seeds:
        print(f"left out (a run stopped): seeds {sorted(set(range(1, a.seeds + 1)) - set(seeds))}")
    rows = [r for s in seeds for f in FIBRES for r in runs[(s, f)]]
    with open(Path(a.out) / "asymmetry.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    last = {(r["seed"], r["fibres"]): r for r in rows}
    first = {(r["seed"], r["fibres"]): r for r in rows if r["stage"] == 0}
    growth = {f: [last[(s, f)]["paper"] - first[(s, f)]["paper"] for s in seeds] for f in FIBRES}
    gain = {f: [last[(s, f)]["band_gain"] for s in seeds] for f in FIBRES}
    mid = {f: [last[(s, f)]["mid_half"] - first[(s, f)]["mid_half"] for s in seeds] for f in FIBRES}
    print(f"{len(seeds)} realisations, {a.stages} stages × {a.steps} steps, K {a.bend}, dt {a.dt}: mean ± s.e.")
    for label, q in (("paper ratio growth", growth), ("band gain", gain), ("mid-half growth", mid)):
        diff = [x - y for x, y in zip(q["asymmetric"], q["symmetric"])]
        print(f"  {label}: asymmetric {mean_se(q['asymmetric'])}, symmetric {mean_se(q['symmetric'])}, difference {mean_se(diff)}")


if __name__ == "__main__":
    main()
