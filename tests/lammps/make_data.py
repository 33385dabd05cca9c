#!/usr/bin/env python3
"""Writes the data files of the LAMMPS decks under tests/lammps/ (standard
library only; deterministic): bead chains with bonds and angles in a
periodic box, and a dense atomic system in a box shorter than twice the
pair cutoff. The decks (in.lammps) are written by hand beside them.

    python3 tests/lammps/make_data.py
"""
import math
import random
from pathlib import Path

HERE = Path(__file__).resolve().parent


def chains(rng, n_chains, beads, box, bond, types, angle_types, bond_types):
    """Random-walk chains (bond length ~`bond`), wrapped into [0, box)^3 with image flags."""
    atoms, bonds, angles = [], [], []
    for c in range(n_chains):
        x = [rng.uniform(0, box) for _ in range(3)]
        for b in range(beads):
            if b > 0:
                while True:
                    d = [rng.gauss(0, 1) for _ in range(3)]
                    norm = math.sqrt(sum(v * v for v in d))
                    step = [bond * rng.uniform(0.9, 1.1) * v / norm for v in d]
                    y = [x[a] + step[a] for a in range(3)]
                    # Keep beads of other chains and 1-3 neighbours apart (no LJ overlap).
                    if all(sum((y[a] - p[a]) ** 2 for a in range(3)) > 0.8 ** 2 for p in [q["u"] for q in atoms[:-1]]):
                        break
                x = y
            atom_id = len(atoms) + 1
            atoms.append({"id": atom_id, "mol": c + 1, "type": types[b % len(types)], "u": list(x)})
            if b > 0:
                bonds.append((bond_types[(b - 1) % len(bond_types)], atom_id - 1, atom_id))
            if b > 1:
                angles.append((angle_types[(b - 2) % len(angle_types)], atom_id - 2, atom_id - 1, atom_id))
    return atoms, bonds, angles


def write(path, title, atoms, bonds, angles, box, n_types, n_bond_types, n_angle_types, style, masses, names, charge=False):
    lines = [title, "", f"{len(atoms)} atoms", f"{len(bonds)} bonds", f"{len(angles)} angles", "",
             f"{n_types} atom types", f"{n_bond_types} bond types", f"{n_angle_types} angle types", ""]
    for axis in "xyz":
        lines.append(f"0.0 {box!r} {axis}lo {axis}hi")
    lines += ["", "Masses", ""]
    for t in range(1, n_types + 1):
        lines.append(f"{t} {masses[t - 1]!r}" + (f"  # {names[t - 1]}" if names else ""))
    lines += ["", f"Atoms # {style}", ""]
    for i, a in enumerate(atoms):
        wrapped = [v % box for v in a["u"]]
        image = [math.floor(v / box) for v in a["u"]]
        cols = [str(a["id"])]
        if style in ("molecular", "full"):
            cols.append(str(a["mol"]))
        cols.append(str(a["type"]))
        if style == "full":
            cols.append(repr(0.1 * ((-1) ** i)))
        cols += [repr(v) for v in wrapped] + [str(k) for k in image]
        lines.append(" ".join(cols))
    if bonds:
        lines += ["", "Bonds", ""] + [f"{k + 1} {t} {i} {j}" for k, (t, i, j) in enumerate(bonds)]
    if angles:
        lines += ["", "Angles", ""] + [f"{k + 1} {t} {i} {j} {l}" for k, (t, i, j, l) in enumerate(angles)]
    path.write_text("\n".join(lines) + "\n")


def main():
    rng = random.Random(44)
    box = 9.0
    atoms, bonds, angles = chains(rng, 6, 6, box, 1.05, [1, 2, 3], [1, 2], [1, 2])
    write(HERE / "molecular" / "chains.data", "LAMMPS data file: six chains of three bead types (tests/lammps/make_data.py)",
          atoms, bonds, angles, box, 3, 2, 2, "molecular", [1.0, 1.0, 2.0], ["head", "middle", "tail"])
    atoms, bonds, angles = chains(rng, 5, 6, box, 1.1, [1, 2], [1], [1, 2, 3])
    write(HERE / "full_lepton" / "chains.data", "LAMMPS data file: five charged chains (tests/lammps/make_data.py)",
          atoms, bonds, angles, box, 2, 3, 1, "full", [1.0, 2.0], [], charge=True)
    # A dense atomic system in a box of edge 3 (the cutoff is 2.5): many periodic images.
    small = 3.0
    atoms = []
    while len(atoms) < 24:
        x = [rng.uniform(0, small) for _ in range(3)]
        def dist2(p):
            return sum(min(abs(x[a] - p[a]), small - abs(x[a] - p[a])) ** 2 for a in range(3))
        if all(dist2(p["u"]) > 0.85 ** 2 for p in atoms):
            atoms.append({"id": len(atoms) + 1, "mol": 0, "type": 1 + len(atoms) % 2, "u": x})
    write(HERE / "small_box" / "dense.data", "LAMMPS data file: 24 atoms in a box of edge 3 (tests/lammps/make_data.py)",
          atoms, [], [], small, 2, 0, 0, "atomic", [1.0, 1.0], ["a", "b"])


if __name__ == "__main__":
    main()
