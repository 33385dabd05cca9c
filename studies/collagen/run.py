#!/usr/bin/env python3
"""Collagen clustering study (seed 002, Ouyang et al. 2022; issue #19).

Builds the study's networks with `cellmd build collagen` (two cells, four on
a square, a random array), runs inputs/collagen_two_cells.in on each with
asymmetric fibres (k_tension = 100 k_compression) and symmetric ones
(k_tension = k_compression), cells held in place (the paper's model), and
once more with asymmetric fibres and cells free to move (for the polygon
area). Writes OUT/clustering.csv (the clustering ratio per stage, mean over
the neighbouring cell pairs, and the area of the cells' polygon) and keeps
each run's thermo CSV, xyz dump and topology under OUT/RUN/; plot.py draws
the figures from them. Not part of CI (see README, *Collagen clustering
study*, for the runtime).

    python3 studies/collagen/run.py --cellmd target/release/cellmd --out out/collagen
"""

import argparse
import csv
import math
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies"))
from cellmd_run import run_command, run_deck, thermo_rows  # noqa: E402

DECK = ROOT / "inputs" / "collagen_two_cells.in"
FF = ROOT / "forcefields" / "collagen.ff"
# The deck's two-cell columns, replaced by each layout's pairs and hubs.
COLUMNS = "clustering/fibre/cell1/cell2 xu/hub1 yu/hub1 xu/hub2 yu/hub2"

# The paper's geometry (µm): cells 200 µm across, 600 µm apart (the random
# array: 600–1000 µm between neighbours); the mesh is ours.
COMMON = ["--cell-radius", "100", "--density", "0.1", "--fibre-length", "200", "--node-spacing", "10", "--seed", "1"]
LAYOUTS = {
    "pair": ["--layout", "pair", "--separation", "600", "--size", "1000", "600"],
    "square": ["--layout", "square", "--separation", "600", "--size", "1000", "1000"],
    "random": ["--layout", "random", "--cells", "5", "--separation", "600", "--size", "1800", "1400"],
}
NEIGHBOUR = 1000.0  # µm: cells this close are a pair whose band is measured (random array)
FIBRES = {"asymmetric": 1.0, "symmetric": 100.0}  # k_compression, pN/µm (k_tension 100)


def hubs_of(top):
    """Hub positions (x, y) of the topology's cells, in id order."""
    hubs = []
    with open(top) as f:
        for line in f:
            w = line.split()
            if len(w) >= 5 and w[1] == "hub":
                hubs.append((float(w[2]), float(w[3])))
    return hubs


def pairs_of(layout, hubs):
    """The neighbouring pairs (1-based) whose band is measured: the sides of
    the square, the pair, or every two random cells within NEIGHBOUR."""
    n = len(hubs)
    if layout == "square":
        return [(k + 1, (k + 1) % n + 1) for k in range(n)]
    return [(i + 1, j + 1) for i in range(n) for j in range(i + 1, n) if math.dist(hubs[i], hubs[j]) <= NEIGHBOUR]


def polygon_area(points):
    """Area of the convex hull of the points (shoelace over the hull)."""
    pts = sorted(set(points))
    if len(pts) < 3:
        return 0.0

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    hull = []
    for seq in (pts, pts[::-1]):
        start = len(hull)
        for p in seq:
            while len(hull) >= start + 2 and cross(hull[-2], hull[-1], p) <= 0:
                hull.pop()
            hull.append(p)
        hull.pop()
    return abs(sum(hull[k][0] * hull[k - 1][1] - hull[k - 1][0] * hull[k][1] for k in range(len(hull)))) / 2.0


def run(cellmd, out, layout, fibres, mobile, steps, stages):
    name = f"{layout}_{fibres}" + ("_mobile" if mobile else "")
    point = out / name
    point.mkdir(parents=True, exist_ok=True)
    top = point / "collagen.top"
    run_command([cellmd, "build", "collagen", *LAYOUTS[layout], *COMMON, "-o", top])
    hubs = hubs_of(top)
    pairs = pairs_of(layout, hubs)
    columns = [f"clustering/fibre/cell{a}/cell{b}" for a, b in pairs]
    columns += [f"{axis}u/hub{c + 1}" for c in range(len(hubs)) for axis in "xy"]
    text = DECK.read_text()
    if text.count(COLUMNS) != 1:
        sys.exit(f"{DECK}: expected the thermo columns `{COLUMNS}` once")
    deck = point / "collagen.in"
    deck.write_text(text.replace(COLUMNS, " ".join(columns)))
    variables = {
        "top": top,
        "ff": FF,
        "ncells": len(hubs),
        "kc": FIBRES[fibres],
        "mobile": int(mobile),
        "steps": steps,
        "stages": stages,
        "name": name,
    }
    wall = run_deck(cellmd, deck, point, variables)
    by_step = thermo_rows(point / f"{name}.thermo.csv")
    area0 = polygon_area(hubs)
    rows = []
    for stage, r in enumerate(by_step):
        ratios = [float(r[c]) for c in columns if c.startswith("clustering/")]
        corners = [(float(r[f"xu/hub{c + 1}"]), float(r[f"yu/hub{c + 1}"])) for c in range(len(hubs))]
        rows.append(
            {
                "layout": layout,
                "fibres": fibres,
                "mobile": int(mobile),
                "stage": stage,
                "radius": round(100 * 0.95**stage, 6),
                "ratio_mean": round(sum(ratios) / len(ratios), 6),
                "ratio_min": round(min(ratios), 6),
                "ratio_max": round(max(ratios), 6),
                "pairs": len(ratios),
                "area_fraction": round(polygon_area(corners) / area0, 6) if area0 > 0 else "",
                "resets": int(r["resets"]),
                "wall_s": round(wall, 1),
            }
        )
    print(f"{name}: {len(hubs)} cells, {len(pairs)} pairs, final ratio {rows[-1]['ratio_mean']}, {wall:.1f} s", flush=True)
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cellmd", default=str(ROOT / "target" / "release" / "cellmd"))
    p.add_argument("--out", default=str(ROOT / "out" / "collagen"))
    p.add_argument("--steps", type=int, default=5000, help="steps per stage")
    p.add_argument("--stages", type=int, default=10)
    p.add_argument("--layouts", default="pair,square,random")
    p.add_argument("--workers", type=int, default=2)
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    jobs = []
    for layout in a.layouts.split(","):
        for fibres in FIBRES:
            jobs.append((layout, fibres, False))
        if layout != "pair":
            jobs.append((layout, "asymmetric", True))
    with ThreadPoolExecutor(a.workers) as pool:
        results = list(pool.map(lambda j: run(a.cellmd, out, *j, a.steps, a.stages), jobs))
    rows = [r for rs in results for r in rs]
    with open(out / "clustering.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {out / 'clustering.csv'}")


if __name__ == "__main__":
    main()
