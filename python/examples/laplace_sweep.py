"""Turgor against cell radius: the pressure a cell holds against its cortical
tension falls as 1/R (Young–Laplace, ΔP = 2γ/R).

For each radius R an icosphere cell (`cellmd.build`) with turgor (K, V0 its
sphere's volume, ΔP0 = 0) and surface tension γ is relaxed by FIRE; the cell
shrinks until K(V0 − V)/V0 balances 2γ/R_V. The points run across cores
(`cellmd.sweep`), each in its own folder, and the figure plots the turgor
against 2γ/R_V, the continuum prediction, on the line y = x.

    python python/examples/laplace_sweep.py --out out/laplace            # 6 radii, level-2 meshes
    python python/examples/laplace_sweep.py --out out/laplace --slurm    # write the job array instead
    python python/examples/laplace_sweep.py --quick --out /tmp/laplace   # 2 radii, level 1 (the test)
"""

import argparse
import math

import cellmd
from cellmd.sweep import Sweep

K, GAMMA = 1000.0, 300.0  # turgor bulk modulus (Pa), cortical tension (pN/µm)

FORCEFIELD = """particle node drag 1
body cell turgor k {k} v0 {v0!r}
body cell surface_tension gamma {gamma}
"""

DECK = """units cell
topology cell.top
forcefield cell.ff
box x -{h} {h} f  y -{h} {h} f  z -{h} {h} f
temperature 0
timestep 3e-3
"""


def relax_cell(outdir: str, radius: float, level: int) -> dict:
    """One point: the relaxed cell of initial radius `radius` (µm)."""
    v0 = 4.0 / 3.0 * math.pi * radius**3
    cell = cellmd.build("icosphere", level=level, radius=radius, no_bonds=True)
    files = {"cell.top": cell.text, "cell.ff": FORCEFIELD.format(k=K, v0=v0, gamma=GAMMA)}
    with cellmd.Simulation.from_text(DECK.format(h=4 * radius), files, directory=outdir, output_dir=outdir) as sim:
        sim.minimize(ftol=1e-5, maxiter=200000, dmax=0.01)
        volume = float(sim.body_state()["volume"][0])
        converged = sim.minimize_converged
    r_v = (3.0 * volume / (4.0 * math.pi)) ** (1.0 / 3.0)
    return {"converged": converged, "r_v": r_v, "turgor": K * (v0 - volume) / v0, "laplace": 2.0 * GAMMA / r_v}


def plot(rows: list, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    laplace = [r["laplace"] for r in rows]
    fig, ax = plt.subplots(figsize=(4.5, 3.5))
    ax.plot(laplace, laplace, "-", color="0.6", label="ΔP = 2γ/R")
    ax.plot(laplace, [r["turgor"] for r in rows], "o", label="cellmd (FIRE)")
    for r in rows:
        ax.annotate(f"R={r['radius']:g}", (r["laplace"], r["turgor"]), textcoords="offset points", xytext=(4, -10), fontsize=7)
    ax.set_xlabel("2γ/R_V (Pa)")
    ax.set_ylabel("turgor K(V0 − V)/V0 (Pa)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="out/laplace", help="the sweep's folder")
    parser.add_argument("--quick", action="store_true", help="2 radii on level-1 meshes (seconds)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: every core)")
    parser.add_argument("--slurm", action="store_true", help="write OUT/sweep.sbatch instead of running")
    args = parser.parse_args()
    radii, level = ([3.0, 6.0], 1) if args.quick else ([2.0, 3.0, 4.0, 6.0, 8.0, 12.0], 2)
    sweep = Sweep(relax_cell, [{"radius": r, "level": level} for r in radii], args.out)
    if args.slurm:
        print(f"wrote {sweep.write_slurm()}: sbatch it, then python -m cellmd.sweep gather {args.out}")
        return
    rows = sweep.run_local(workers=args.workers)
    plot(rows, f"{args.out}/laplace.png")
    for r in rows:
        print(f"R = {r['radius']:5.2f} µm: R_V = {r['r_v']:.4f} µm, turgor {r['turgor']:9.4f} Pa, 2γ/R_V {r['laplace']:9.4f} Pa")
    print(f"wrote {args.out}/summary.csv and {args.out}/laplace.png")


if __name__ == "__main__":
    main()
