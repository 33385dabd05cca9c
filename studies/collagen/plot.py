#!/usr/bin/env python3
"""Draws the collagen study's figures from run.py's OUT folder.

- OUT/density.png: fibre density maps (fibre length per 20 µm pixel) at the
  last stage, asymmetric and symmetric fibres for the pair, asymmetric for
  the square and the random array (cells held in place);
- OUT/clustering.png: the clustering ratio S_max/S_min (mean over the
  neighbouring pairs) against the contraction stage, asymmetric against
  symmetric fibres, and the area of the cells' polygon when they may move.

Needs numpy and matplotlib (`bash scripts/reference-venv` prints the
reference venv's python).

    python3 studies/collagen/plot.py out/collagen
"""

import csv
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PIXEL = 20.0  # µm


def fibres_of(top):
    """The (i, j) ids of the topology's fibre bonds."""
    bonds, section = [], None
    with open(top) as f:
        for line in f:
            w = line.split()
            if not w or w[0].startswith("#"):
                continue
            if w[0] == "[":
                section = w[1]
            elif section == "bonds" and w[0] == "fibre":
                bonds.append((int(w[1]), int(w[2])))
    return bonds


def frames(xyz):
    """Every frame of an xyz dump (`species x y z type id`), each id → (x, y)."""
    lines = Path(xyz).read_text().splitlines()
    out, k = [], 0
    while k < len(lines):
        n = int(lines[k])
        out.append({int(w[5]): (float(w[1]), float(w[2])) for w in (line.split() for line in lines[k + 2 : k + 2 + n])})
        k += n + 2
    return out


def sample(pos, bonds, spacing):
    """Points along each bond (i, j) at most `spacing` apart, each carrying its
    share of the bond's length: (points, weights) for length histograms."""
    a = np.array([pos[i] for i, _ in bonds])
    b = np.array([pos[j] for _, j in bonds])
    lengths = np.linalg.norm(b - a, axis=1)
    n = np.maximum(1, np.ceil(lengths / spacing)).astype(int)
    t = np.concatenate([(np.arange(k) + 0.5) / k for k in n])
    pts = np.repeat(a, n, axis=0) + np.repeat(b - a, n, axis=0) * t[:, None]
    return pts, np.repeat(lengths / n, n)


def density_map(run_dir):
    """Fibre length per pixel of the run's last frame, and its extent."""
    name = run_dir.name
    pos = frames(run_dir / f"{name}.xyz")[-1]
    pts, weights = sample(pos, fibres_of(run_dir / "collagen.top"), PIXEL / 2)
    xs = np.arange(np.floor(pts[:, 0].min() / PIXEL) * PIXEL, pts[:, 0].max() + PIXEL, PIXEL)
    ys = np.arange(np.floor(pts[:, 1].min() / PIXEL) * PIXEL, pts[:, 1].max() + PIXEL, PIXEL)
    h, _, _ = np.histogram2d(pts[:, 0], pts[:, 1], bins=[xs, ys], weights=weights)
    return h.T / (PIXEL * PIXEL), [xs[0], xs[-1], ys[0], ys[-1]]


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/collagen")
    with open(out / "clustering.csv") as f:
        rows = list(csv.DictReader(f))

    panels = [d for d in ("pair_asymmetric", "pair_symmetric", "square_asymmetric", "random_asymmetric") if (out / d).is_dir()]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8), squeeze=False)
    for ax, name in zip(axes[0], panels):
        h, extent = density_map(out / name)
        im = ax.imshow(h, origin="lower", extent=extent, cmap="viridis", vmin=0, vmax=np.percentile(h, 99.5))
        last = [r for r in rows if f"{r['layout']}_{r['fibres']}" == name and r["mobile"] == "0"][-1]
        ax.set_title(f"{name.replace('_', ', ')}\nstage {last['stage']}: S_max/S_min {float(last['ratio_mean']):.2f}", fontsize=9)
        ax.set_xlabel("x (µm)")
        ax.set_aspect("equal")
        fig.colorbar(im, ax=ax, shrink=0.8, label="fibre length per area (µm⁻¹)")
    axes[0][0].set_ylabel("y (µm)")
    fig.tight_layout()
    fig.savefig(out / "density.png", dpi=110)

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    colours = {"pair": "#4c72b0", "square": "#c44e52", "random": "#55a868"}
    for layout, colour in colours.items():
        for fibres, style in (("asymmetric", "-o"), ("symmetric", "--s")):
            pts = [r for r in rows if r["layout"] == layout and r["fibres"] == fibres and r["mobile"] == "0"]
            if pts:
                ax.plot([int(r["stage"]) for r in pts], [float(r["ratio_mean"]) for r in pts], style, color=colour, ms=3, label=f"{layout}, {fibres}")
        pts = [r for r in rows if r["layout"] == layout and r["mobile"] == "1"]
        if pts:
            ax2.plot([int(r["stage"]) for r in pts], [100 * float(r["area_fraction"]) for r in pts], "-o", color=colour, ms=3, label=layout)
    ax.axhline(1.0, color="grey", lw=0.5)
    ax.set_xlabel("contraction stage (radius × 0.95 per stage)")
    ax.set_ylabel("clustering S_max/S_min (mean over pairs)")
    ax.legend(fontsize=7)
    ax2.set_xlabel("contraction stage")
    ax2.set_ylabel("area of the cells' polygon (% of initial)")
    ax2.set_title("cells free to move, asymmetric fibres", fontsize=9)
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "clustering.png", dpi=110)
    print(f"wrote {out / 'density.png'} and {out / 'clustering.png'}")


if __name__ == "__main__":
    main()
