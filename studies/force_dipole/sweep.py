#!/usr/bin/env python3
"""Stress decay around a force dipole in a fibre network (seed 000, checkpoint 6).

For each seed, builds a diluted triangular lattice of bending-stiff fibres with
a contractile bond at its centre (`cellmd build lattice --radius R
--bond-probability p --bending --dipole --seed S`), relaxes it with
inputs/force_dipole.in (FIRE at T = 0, clamped rim) and reads the dump's
per-node `sxx` (stress × area) over the area per node √3/2 (a = 1). |σ_xx| is
averaged over rings logarithmically spaced between 4a and R/2 and the log-log
slope fitted by least squares, per seed and for the seeds' mean profile;
seed 000's window is [−2.5, −1.5], the 2D continuum's r⁻² its centre. The full
lattice without bending (p = 1, an isotropic elastic sheet) is the reference.
Writes OUT/force_dipole.csv (ring profiles) and OUT/force_dipole.png. Needs
numpy and matplotlib (`bash scripts/reference-venv` prints the reference venv).

    python3 studies/force_dipole/sweep.py --cellmd target/release/cellmd --out out/force_dipole
"""

import argparse
import csv
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from cellmd_run import run_command, run_deck  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DECK = ROOT / "inputs" / "force_dipole.in"
RINGS = 6
R_IN = 4.0


def last_frame(path):
    """Columns of the dump's last frame, as a dict of arrays."""
    lines = path.read_text().splitlines()
    start = max(i for i, line in enumerate(lines) if line.startswith("ITEM: ATOMS"))
    names = lines[start].split()[2:]
    data = np.array([[float(v) for v in line.split()] for line in lines[start + 1:]])
    return dict(zip(names, data.T))


def profile(cellmd, out, radius, p, bending, seed):
    d = out / f"p{p:g}_{'fibres' if bending else 'springs'}_s{seed}"
    d.mkdir(parents=True, exist_ok=True)
    top = d / "lattice.top"
    run_command([cellmd, "build", "lattice", "--radius", str(radius), "--spacing", "1", "--bond-probability", str(p), "--dipole",
                 "--seed", str(seed), "-o", top] + (["--bending"] if bending else []))
    run_deck(cellmd, DECK, d, {"topology": top})
    f = last_frame(d / "force_dipole.lammpstrj")
    r = np.hypot(f["x"], f["y"])
    sxx = np.abs(f["sxx"]) / (3 ** 0.5 / 2)
    edges = R_IN * (radius / 2 / R_IN) ** (np.arange(RINGS + 1) / RINGS)
    rows = []
    for k in range(RINGS):
        m = (r >= edges[k]) & (r < edges[k + 1])
        rows.append({"p": p, "bending": int(bending), "seed": seed, "ring": k, "r": r[m].mean(), "abs_sxx": sxx[m].mean(), "nodes": int(m.sum())})
    return rows


def slope(rows):
    x = np.log([r["r"] for r in rows])
    y = np.log([r["abs_sxx"] for r in rows])
    return np.polyfit(x, y, 1)[0]


def main():
    a = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--cellmd", default=str(ROOT / "target" / "release" / "cellmd"))
    a.add_argument("--out", default=str(ROOT / "out" / "force_dipole"))
    a.add_argument("--radius", type=float, default=32.0)
    a.add_argument("--probability", type=float, default=0.8)
    a.add_argument("--seeds", type=int, default=8)
    a.add_argument("--workers", type=int, default=os.cpu_count())
    o = a.parse_args()
    out = Path(o.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(1.0, False, 1)] + [(o.probability, True, s) for s in range(1, o.seeds + 1)]
    with ThreadPoolExecutor(o.workers) as pool:
        runs = list(pool.map(lambda j: profile(o.cellmd, out, o.radius, *j), jobs))
    with open(out / "force_dipole.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(runs[0][0]))
        w.writeheader()
        for rows in runs:
            w.writerows(rows)
    full, fibres = runs[0], runs[1:]
    slopes = [slope(rows) for rows in fibres]
    mean = [{"r": np.mean([rows[k]["r"] for rows in fibres]), "abs_sxx": np.mean([rows[k]["abs_sxx"] for rows in fibres])}
            for k in range(RINGS)]
    print(f"full lattice (no bending): slope {slope(full):.3f}")
    print(f"p = {o.probability} fibres: per-seed slopes {', '.join(f'{s:.3f}' for s in slopes)}; "
          f"mean {np.mean(slopes):.3f} ± {np.std(slopes, ddof=1):.3f} (std); slope of the mean profile {slope(mean):.3f}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for rows in fibres:
        ax.loglog([r["r"] for r in rows], [r["abs_sxx"] for r in rows], color="#bbb", lw=0.8)
    ax.loglog([r["r"] for r in mean], [r["abs_sxx"] for r in mean], "o-", color="#c44e52",
              label=f"fibres p = {o.probability:g}, mean of {len(fibres)} (slope {slope(mean):.2f})")
    ax.loglog([r["r"] for r in full], [r["abs_sxx"] for r in full], "s-", color="#4c72b0",
              label=f"full lattice, no bending (slope {slope(full):.2f})")
    r0, s0 = mean[0]["r"], mean[0]["abs_sxx"]
    rr = np.array([mean[0]["r"], mean[-1]["r"]])
    ax.loglog(rr, s0 * (rr / r0) ** -2, "k--", lw=1, label="r⁻² (2D continuum)")
    ax.set_xlabel("distance from the dipole r (µm = lattice spacings)")
    ax.set_ylabel("ring mean |σ_xx| (pN/µm)")
    ax.set_title(f"Force dipole (2 pN × 2a) in a fibre network, R = {o.radius:g} a")
    ax.legend(frameon=False, fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "force_dipole.png", dpi=130)
    print(f"-> {out / 'force_dipole.csv'}, {out / 'force_dipole.png'}")


if __name__ == "__main__":
    main()
