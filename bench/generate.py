#!/usr/bin/env python3
"""Writes one benchmark system twice: as a cellmd topology/force field/deck and
as a LAMMPS data file + input, with identical physics (units lj, kT, drag,
bonds, angles, pairs, special bonds, skin, time step).

    python3 bench/generate.py network NX NY NZ DIR   # cubic network, NX*NY*NZ beads
    python3 bench/generate.py melt NX NY NZ DIR      # chains along x, NX beads each

Both decks take the step count as a variable (`steps`; cellmd `--var`,
LAMMPS `-var`) and print the potential energy at step 0 and at the end with
all 17 significant digits (cellmd: thermo CSV; LAMMPS: log), so the harness
can check the physics before timing it.

Conventions mapped (see docs/src/coming-from/lammps.md): cellmd `harmonic` k = 2·K of LAMMPS bond
harmonic; `soft` = pair soft (A, rc); `wca` = lj/cut at 2^(1/6)σ with
pair_modify shift yes; `wlc_bending` κ/ℓ = K of angle cosine; cellmd's default
special_bonds (exclude 1-2 only) = `special_bonds lj 0.0 1.0 1.0`.
"""

import os
import random
import sys

TWO_SIXTH = 2.0 ** (1.0 / 6.0)

# (a)/(c) cubic network: lattice spacing 1, harmonic bonds to the 6 lattice
# neighbours (periodic), soft repulsion reaching the √2 and √3 shells.
# The Verlet skin of each system is the fastest for LAMMPS among 0.3, 0.5,
# 0.7/0.8, 1.0 on this benchmark (see BENCHMARKS.md); both engines use it.
NETWORK = dict(k=10.0, r0=1.0, A=1.0, rc=1.5, kT=0.1, gamma=1.0, dt=0.005, jitter=0.1, skin=1.0)
# (b) semiflexible melt: density 0.85, chains straight along x, harmonic bonds,
# cosine bending, WCA between all non-bonded beads.
MELT = dict(k=100.0, r0=1.0, kappa=2.0, eps=1.0, sigma=1.0, kT=1.0, gamma=1.0, dt=1e-4, jitter=0.05, density=0.85, skin=0.8)


def network(nx, ny, nz, rng):
    p = NETWORK
    index = lambda x, y, z: x + nx * (y + ny * z)
    pos, bonds = [], []
    for z in range(nz):
        for y in range(ny):
            for x in range(nx):
                pos.append(tuple(c + rng.uniform(-p["jitter"], p["jitter"]) for c in (x, y, z)))
                i = index(x, y, z)
                bonds += [(i, index((x + 1) % nx, y, z)), (i, index(x, (y + 1) % ny, z)), (i, index(x, y, (z + 1) % nz))]
    return dict(box=(nx, ny, nz), pos=pos, bonds=bonds, angles=[], params=p, kind="network")


def melt(nx, ny, nz, rng):
    p = MELT
    a = (1.0 / p["density"]) ** (1.0 / 3.0)
    pos, bonds, angles = [], [], []
    for z in range(nz):
        for y in range(ny):
            for x in range(nx):
                pos.append(tuple(a * c + rng.uniform(-p["jitter"], p["jitter"]) for c in (x, y, z)))
                i = len(pos) - 1
                if x > 0:
                    bonds.append((i - 1, i))
                if x > 1:
                    angles.append((i - 2, i - 1, i))
    return dict(box=(a * nx, a * ny, a * nz), pos=pos, bonds=bonds, angles=angles, params=p, kind="melt")


def write_cellmd(system, out):
    p, (lx, ly, lz) = system["params"], system["box"]
    with open(os.path.join(out, "system.top"), "w") as f:
        f.write(f"# {system['kind']} benchmark (bench/generate.py)\n[ box ]\n")
        f.write(f"x 0 {lx!r} p\ny 0 {ly!r} p\nz 0 {lz!r} p\n[ particles ]\n")
        f.writelines(f"{i + 1} bead {x!r} {y!r} {z!r}\n" for i, (x, y, z) in enumerate(system["pos"]))
        f.write("[ bonds ]\n")
        f.writelines(f"b {i + 1} {j + 1}\n" for i, j in system["bonds"])
        if system["angles"]:
            f.write("[ angles ]\n")
            f.writelines(f"a {i + 1} {j + 1} {k + 1}\n" for i, j, k in system["angles"])
    with open(os.path.join(out, "system.ff"), "w") as f:
        f.write(f"particle bead drag {p['gamma']!r}\nbond b harmonic k {p['k']!r} r0 {p['r0']!r}\n")
        if system["kind"] == "network":
            f.write(f"pair bead bead soft A {p['A']!r} rc {p['rc']!r}\n")
        else:
            f.write(f"angle a wlc_bending kappa {p['kappa']!r} l0 1\n")
            f.write(f"pair bead bead wca epsilon {p['eps']!r} sigma {p['sigma']!r}\n")
    with open(os.path.join(out, "bench.in"), "w") as f:
        f.write(
            "variable steps equal 2000\nunits lj\ntopology system.top\nforcefield system.ff\n"
            f"temperature {p['kT']!r}\ntimestep {p['dt']!r}\nseed 12345\n"
            f"neighbor skin {p['skin']!r} every 1 check yes\nthermo 0 step pe\nthermo_file thermo.csv\nrun ${{steps}}\n"
        )


def write_lammps(system, out):
    p, (lx, ly, lz) = system["params"], system["box"]
    n_angles = len(system["angles"])
    with open(os.path.join(out, "system.data"), "w") as f:
        f.write(f"{system['kind']} benchmark (bench/generate.py)\n\n{len(system['pos'])} atoms\n{len(system['bonds'])} bonds\n")
        f.write(f"{n_angles} angles\n1 atom types\n1 bond types\n{1 if n_angles else 0} angle types\n\n")
        f.write(f"0 {lx!r} xlo xhi\n0 {ly!r} ylo yhi\n0 {lz!r} zlo zhi\n\nMasses\n\n1 1\n\nAtoms # angle\n\n")
        f.writelines(f"{i + 1} 1 1 {x!r} {y!r} {z!r}\n" for i, (x, y, z) in enumerate(system["pos"]))
        f.write("\nBonds\n\n")
        f.writelines(f"{b + 1} 1 {i + 1} {j + 1}\n" for b, (i, j) in enumerate(system["bonds"]))
        if n_angles:
            f.write("\nAngles\n\n")
            f.writelines(f"{a + 1} 1 {i + 1} {j + 1} {k + 1}\n" for a, (i, j, k) in enumerate(system["angles"]))
    if system["kind"] == "network":
        pair = f"pair_style soft {p['rc']!r}\npair_coeff * * {p['A']!r} {p['rc']!r}\n"
        angle = ""
    else:
        rc = TWO_SIXTH * p["sigma"]
        pair = f"pair_style lj/cut {rc!r}\npair_coeff * * {p['eps']!r} {p['sigma']!r} {rc!r}\npair_modify shift yes\n"
        angle = f"angle_style cosine\nangle_coeff 1 {p['kappa']!r}\n"
    with open(os.path.join(out, "bench.lmp"), "w") as f:
        f.write(
            "variable steps index 2000\nunits lj\natom_style angle\nboundary p p p\n"
            "bond_style harmonic\nread_data system.data\n"
            f"bond_coeff 1 {p['k'] / 2!r} {p['r0']!r}\n{angle}{pair}special_bonds lj/coul 0.0 1.0 1.0\n"
            f"neighbor {p['skin']!r} bin\nneigh_modify every 1 delay 0 check yes\ntimestep {p['dt']!r}\n"
            f"fix bd all brownian {p['kT']!r} 12345 gamma_t {p['gamma']!r} rng uniform\n"
            "thermo_style custom step pe\nthermo_modify norm no format float %.17g\nthermo 0\nrun ${steps}\n"
        )


def main(argv):
    if len(argv) != 6 or argv[1] not in ("network", "melt"):
        sys.exit(__doc__)
    kind, (nx, ny, nz), out = argv[1], map(int, argv[2:5]), argv[5]
    os.makedirs(out, exist_ok=True)
    system = (network if kind == "network" else melt)(nx, ny, nz, random.Random(2025))
    write_cellmd(system, out)
    write_lammps(system, out)


if __name__ == "__main__":
    main(sys.argv)
