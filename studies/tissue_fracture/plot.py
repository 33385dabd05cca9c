#!/usr/bin/env python3
"""Draws the phase diagram OUT/phase.png from OUT/phase.csv (sweep.py).

Each point is coloured by its label (elastic, ductile, brittle) and annotated
with its rearrangements per broken junction; axes: force gradient (log) ×
threshold strain. Needs matplotlib (`bash scripts/reference-venv` prints the
reference venv's python).

    python3 studies/tissue_fracture/plot.py out/tissue_fracture
"""

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"elastic": "#4c72b0", "ductile": "#55a868", "brittle": "#c44e52"}


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/tissue_fracture")
    with open(out / "phase.csv") as f:
        rows = list(csv.DictReader(f))
    fig, ax = plt.subplots(figsize=(7.6, 4.8))
    for phase, colour in COLOURS.items():
        pts = [r for r in rows if r["phase"] == phase]
        ax.scatter([float(r["g"]) for r in pts], [float(r["strain"]) for r in pts], s=380, marker="s", c=colour, label=phase)
    for r in rows:
        if r["phase"] != "elastic":
            mark = "" if float(r["pieces"]) == 1 else f"\n{float(r['pieces']):.0f} pc"
            ax.annotate(f"{float(r['ratio']):.2f}{mark}", (float(r["g"]), float(r["strain"])), ha="center", va="center", fontsize=6, color="white")
    r0 = rows[0]
    ax.set_xscale("log")
    ax.set_xlabel("force gradient g (pN/µm), f_x = g·x")
    ax.set_ylabel("threshold strain")
    ramp = float(r0["ramp"])
    pulling = "steady pulling" if ramp == 0 else f"pull ramped over {ramp:g} s"
    ax.set_title(f"Tissue fracture (seed 001): {pulling}, τ_mature = {float(r0['tau']):g} s, k_on = {float(r0['k_on']):g}/s\n"
                 "numbers: rearrangements per broken junction (and pieces, when separated)", fontsize=9)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, markerscale=0.4)
    fig.tight_layout()
    fig.savefig(out / "phase.png", dpi=120)
    print(out / "phase.png")


if __name__ == "__main__":
    main()
