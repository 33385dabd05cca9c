#!/usr/bin/env python3
"""Contractile network stress against connectivity z (seed 000, checkpoint 12).

For each bond probability p and seed, builds a diluted triangular lattice
(`cellmd build lattice --radius R --bond-probability p --seed S`), relaxes it
with inputs/contractile_lattice.in (every link contractile by ε, clamped
rim, FIRE at T = 0) and reads the relaxed thermo row: the network stress
σ = −(pxx + pyy)·V/(2·N·√3/2) (pN/µm, V the box volume, N the nodes; a = 1).
The full lattice's σ_full = n_bonds·k·ε/(√3·N) is exact (nothing moves).
Writes OUT/contractile_lattice.csv and OUT/contractile_lattice.png (σ/σ_full
against z, one dot per seed, the mean as a line; z_c = 3.96 of central-force
rigidity percolation, Jacobs & Thorpe 1995, marked; the effective-medium
line (z − 4)/2 is the central-force modulus of Feng, Thorpe & Garboczi,
Phys. Rev. B 31, 276 (1985), for comparison). Needs numpy and
matplotlib (`bash scripts/reference-venv` prints the reference venv).

    python3 studies/contractile_lattice/sweep.py --cellmd target/release/cellmd --out out/contractile_lattice
"""

import argparse
import csv
import os
import re
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from cellmd_run import run_command, run_deck, thermo_rows  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DECK = ROOT / "inputs" / "contractile_lattice.in"
K = 100.0  # pN/µm, forcefields/fibre_lattice.ff's link stiffness
Z_C = 3.961  # Jacobs & Thorpe 1995, triangular lattice, central forces


def point(cellmd, out, radius, strain, iterations, p, seed):
    d = out / f"p{p:g}_s{seed}"
    d.mkdir(parents=True, exist_ok=True)
    top = d / "lattice.top"
    said = run_command([cellmd, "build", "lattice", "--radius", str(radius), "--spacing", "1", "--bond-probability", str(p),
                        "--seed", str(seed), "-o", top])
    nodes = int(re.search(r"(\d+) nodes in a disc", said).group(1))
    bonds = int(re.search(r"(\d+) bonds `link`", said).group(1))
    z = float(re.search(r"connectivity z = ([0-9.]+)", said).group(1))
    box = [float(line.split()[2]) - float(line.split()[1]) for line in top.read_text().splitlines()
           if re.match(r"^[xyz] -?[0-9.]+ -?[0-9.]+ f$", line)]
    run_deck(cellmd, DECK, d, {"topology": top, "strain": strain, "fire_iterations": iterations})
    last = thermo_rows(d / "contractile_lattice.thermo.csv")[-1]
    volume = box[0] * box[1] * box[2]
    sigma = -(last["pxx"] + last["pyy"]) * volume / (2 * nodes * 3 ** 0.5 / 2)
    return {"p": p, "seed": seed, "nodes": nodes, "bonds": bonds, "z": z, "sigma": sigma, "fmax_incl_rim": last["fmax"]}


def main():
    a = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--cellmd", default=str(ROOT / "target" / "release" / "cellmd"))
    a.add_argument("--out", default=str(ROOT / "out" / "contractile_lattice"))
    a.add_argument("--radius", type=float, default=20.0)
    a.add_argument("--strain", type=float, default=0.01)
    a.add_argument("--probabilities", default="0.45,0.5,0.55,0.6,0.625,0.65,0.675,0.7,0.725,0.75,0.8,0.85,0.9,0.95,1")
    a.add_argument("--seeds", type=int, default=4)
    a.add_argument("--fire-iterations", type=int, default=200000, help="FIRE's cap; fmax in the CSV says how far from ftol a run stopped")
    a.add_argument("--workers", type=int, default=os.cpu_count())
    o = a.parse_args()
    out = Path(o.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(float(p), s) for p in o.probabilities.split(",") for s in range(1, o.seeds + 1)]
    with ThreadPoolExecutor(o.workers) as pool:
        rows = list(pool.map(lambda j: point(o.cellmd, out, o.radius, o.strain, o.fire_iterations, *j), jobs))
    full = {r["seed"]: r for r in rows if r["p"] == 1.0}
    for r in rows:
        ref = full.get(r["seed"]) or next(iter(full.values()))
        r["sigma_full"] = ref["bonds"] * K * o.strain / (3 ** 0.5 * ref["nodes"])
        r["ratio"] = r["sigma"] / r["sigma_full"]
    with open(out / "contractile_lattice.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("p      z(mean)  sigma/sigma_full (mean over seeds)")
    means = []
    for p in sorted({r["p"] for r in rows}):
        pts = [r for r in rows if r["p"] == p]
        zm = sum(r["z"] for r in pts) / len(pts)
        rm = sum(r["ratio"] for r in pts) / len(pts)
        means.append((zm, rm))
        print(f"{p:<6g} {zm:7.3f}  {rm:.4f}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot([r["z"] for r in rows], [r["ratio"] for r in rows], ".", color="#999", label="one disc (seed)")
    ax.plot(*zip(*means), "o-", color="#c44e52", label="mean over seeds")
    ax.axvline(Z_C, ls="--", color="k", lw=1, label="z_c = 3.96 (rigidity percolation)")
    ax.plot([4, 6], [0, 1], ":", color="#4c72b0", label="effective medium (z − 4)/2 (modulus, Feng et al. 1985)")
    ax.set_xlabel("connectivity z (bonds per free node)")
    ax.set_ylabel("network stress σ / σ_full")
    ax.set_title(f"Contractile lattice, R = {o.radius:g} a, ε = {o.strain:g}: floppy → rigid")
    ax.legend(frameon=False)
    fig.tight_layout()
    fig.savefig(out / "contractile_lattice.png", dpi=130)
    print(f"{len(rows)} runs -> {out / 'contractile_lattice.csv'}, {out / 'contractile_lattice.png'}")


if __name__ == "__main__":
    main()
