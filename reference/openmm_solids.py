#!/usr/bin/env python3
"""OpenMM golden data for the volume-element (`tetra`) interaction types.

LAMMPS has no finite-strain solid element, so `neo_hookean` and
`linear_elastic` are checked against OpenMM: each element's energy V_0·W(F)
is one CustomCompoundBondForce term of its four particles, written from
their coordinates x1 … z4 with the element's rest shape (D_m⁻¹ and V_0) as
per-bond parameters; OpenMM differentiates it (Lepton) for the forces, and
a CustomIntegrator takes the same deterministic overdamped Euler steps as
cellmd at kT = 0, x <- x + dt*F/gamma, on the Reference platform (double
precision).

    python3 reference/openmm_solids.py            writes reference/NAME/ (decks and
                                                  topologies) and reference/NAME.yaml.new
    python3 reference/openmm_solids.py --list     prints the types it covers

Each case is a block of (n + 1)³ jittered lattice nodes, every cube split
into its six Kuhn tetrahedra (as `cellmd build ball` before its map): the
topology holds the rest shape; the deck then moves every node by its own
`displace_atoms` (a rotation of the block plus a random strain), so the
elements start deformed. `small`: n = 2 (27 nodes, 48 elements); `random`:
n = 4 (125 nodes, 384 elements) in a periodic box, across three of its
faces: OpenMM's x1 … z4 are not minimum images, so OpenMM sees the block
whole (no periodic boundaries) while cellmd wraps it into the box and takes
minimum images around each element's first corner. The topology writes the
rest positions unwrapped, as cellmd requires of an element (its rest shape
is its corners as written). The energies are also evaluated here with numpy from
cellmd's documented formulas, and the script stops if OpenMM disagrees.
"""
import argparse
import datetime
import json
import math
import os
import random

import numpy as np
import openmm as mm

from openmm_surfaces import document, fmt, snapshot  # the golden format, shared

HERE = os.path.dirname(os.path.abspath(__file__))
STEPS = 100
# Parameters of each type (reference/cases.json, keyed by the interaction's name).
with open(os.path.join(HERE, "cases.json")) as _f:
    PARAMS = {name: case["params"] for name, case in json.load(_f).items() if case["script"] == "openmm_solids.py"}
KUHN = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]

# Ds[a][c] = (x_{c+2} − x_1)_a (rows x, y, z; columns the three edges from corner 1);
# F = Ds·M with M = D_m⁻¹ (per-bond m11 … m33).
EDGES = "; ".join(f"d{a + 1}{c + 1} = {'xyz'[a]}{c + 2} - {'xyz'[a]}1" for a in range(3) for c in range(3))
GRADIENT = "; ".join(f"f{a + 1}{b + 1} = " + " + ".join(f"d{a + 1}{c + 1}*m{c + 1}{b + 1}" for c in range(3))
                     for a in range(3) for b in range(3))
DET = "j = f11*(f22*f33 - f23*f32) - f12*(f21*f33 - f23*f31) + f13*(f21*f32 - f22*f31)"
I1 = "i1 = " + " + ".join(f"f{a}{b}^2" for a in (1, 2, 3) for b in (1, 2, 3))
GREEN = "; ".join(f"g{a}{b} = 0.5*(" + " + ".join(f"f{k}{a}*f{k}{b}" for k in (1, 2, 3)) + (" - 1)" if a == b else ")")
                  for a in (1, 2, 3) for b in (1, 2, 3))
ENERGY = {
    "neo_hookean": f"v0*(0.5*mu*(i1 - 3) - mu*log(j) + 0.5*lam*log(j)^2); {I1}; {DET}; {GRADIENT}; {EDGES}",
    "linear_elastic": "v0*(mu*(" + " + ".join(f"g{a}{b}^2" for a in (1, 2, 3) for b in (1, 2, 3))
    + f") + 0.5*lam*(g11 + g22 + g33)^2); {GREEN}; {GRADIENT}; {EDGES}",
}


def lame(p):
    e, nu = p["e"], p["nu"]
    return e / (2.0 * (1.0 + nu)), e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))


def neo_hookean_density(mu, lam, f):
    j = np.linalg.det(f)
    return 0.5 * mu * (np.sum(f * f) - 3) - mu * math.log(j) + 0.5 * lam * math.log(j) ** 2


def linear_elastic_density(mu, lam, f):
    g = 0.5 * (f.T @ f - np.eye(3))
    return mu * np.sum(g * g) + 0.5 * lam * np.trace(g) ** 2


# cellmd's documented strain-energy density W(F), by interaction name.
DENSITY_NUMPY = {"neo_hookean": neo_hookean_density, "linear_elastic": linear_elastic_density}


def energy_numpy(name, p, rest, x, elements):
    mu, lam = lame(p)
    total = 0.0
    for t in elements:
        dm = np.array([rest[t[k]] for k in (1, 2, 3)]).T - np.array(rest[t[0]])[:, None]
        ds = np.array([x[t[k]] for k in (1, 2, 3)]).T - np.array(x[t[0]])[:, None]
        f = ds @ np.linalg.inv(dm)
        v0 = abs(np.linalg.det(dm)) / 6.0
        total += v0 * DENSITY_NUMPY[name](mu, lam, f)
    return total


def block_mesh(n, size, centre, rng):
    """Jittered lattice nodes and the Kuhn tetrahedra of its cubes (plain floats)."""
    h = size / n
    index = lambda i, j, k: (i * (n + 1) + j) * (n + 1) + k
    rest = []
    for i in range(n + 1):
        for j in range(n + 1):
            for k in range(n + 1):
                rest.append(tuple(centre[a] + (v - n / 2) * h + rng.uniform(-0.15, 0.15) * h for a, v in enumerate((i, j, k))))
    elements = []
    for i in range(n):
        for j in range(n):
            for k in range(n):
                for order in KUHN:
                    corner = [i, j, k]
                    nodes = [index(i, j, k)]
                    for axis in order:
                        corner[axis] += 1
                        nodes.append(index(*corner))
                    elements.append(nodes)
    return rest, elements


def displacements(rest, centre, rng, amplitude):
    """Each node's move from its rest position (12 decimals, as the deck
    writes it): a rotation about the centre, a random strain and a jitter."""
    axis = np.array([rng.uniform(-1, 1) for _ in range(3)])
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(0.3, 0.6)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rot = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    strain = np.eye(3) + np.array([[rng.uniform(-amplitude, amplitude) for _ in range(3)] for _ in range(3)])
    c = np.array(centre)
    out = []
    for p in rest:
        q = c + rot @ strain @ (np.array(p) - c) + np.array([rng.uniform(-0.5, 0.5) * amplitude for _ in range(3)])
        out.append(tuple(float(f"{v:.12f}") for v in q - np.array(p)))
    return out


def write_case(name, case, rest, moves, elements, dt, box, periodic):
    d = os.path.join(HERE, name)
    lines = [f"# {case} case of {name}: written by reference/openmm_solids.py (positions: the rest shape)", "[ particles ]"]
    lines += [f"{k + 1} a {fmt(p[0])} {fmt(p[1])} {fmt(p[2])}" for k, p in enumerate(rest)]
    lines.append("[ tetrahedra ]")
    lines += ["solid " + " ".join(str(v + 1) for v in t) for t in elements]
    with open(os.path.join(d, f"{case}.top"), "w") as out:
        out.write("\n".join(lines) + "\n")
    flag = "p" if periodic else "f"
    axes = " ".join(f"{a} {fmt(box[0])} {fmt(box[1])} {flag}" for a in "xyz")
    deck = [f"units lj\ntopology {case}.top\nforcefield {name}.ff\nbox {axes}\ntemperature 0\ntimestep {dt}"]
    deck.append("# the deformed start: each node moved from its rest position")
    for k, m in enumerate(moves):
        deck.append(f"group p id {k + 1}\ndisplace_atoms p move {fmt(m[0])} {fmt(m[1])} {fmt(m[2])}")
    deck.append(f"thermo 0\nrun {STEPS}\n")
    with open(os.path.join(d, f"{case}.in"), "w") as out:
        out.write("\n".join(deck))


def system_of(name, p, rest, elements):
    mu, lam = lame(p)
    system = mm.System()
    for _ in rest:
        system.addParticle(1.0)
    force = mm.CustomCompoundBondForce(4, ENERGY[name])
    for par in ["v0", "mu", "lam"] + [f"m{a}{b}" for a in (1, 2, 3) for b in (1, 2, 3)]:
        force.addPerBondParameter(par)
    for t in elements:
        dm = np.array([rest[t[k]] for k in (1, 2, 3)]).T - np.array(rest[t[0]])[:, None]
        m = np.linalg.inv(dm)
        force.addBond(t, [abs(np.linalg.det(dm)) / 6.0, mu, lam] + [m[a, b] for a in range(3) for b in range(3)])
    force.setForceGroup(1)
    system.addForce(force)
    return system


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--date", default=datetime.date.today().isoformat())
    args = ap.parse_args()
    if args.list:
        print(" ".join(PARAMS))
        return
    platform = mm.Platform.getPlatformByName("Reference")
    for name, p in PARAMS.items():
        rng = random.Random(f"cellmd {name}")
        os.makedirs(os.path.join(HERE, name), exist_ok=True)
        with open(os.path.join(HERE, name, f"{name}.ff"), "w") as out:
            out.write(f"particle a drag 1\ntetra solid {name} e {fmt(p['e'])} nu {fmt(p['nu'])}\n")
        docs = []
        # random: in a periodic box of edge 12, across its faces x = 0, y = 0 and z = 0
        # (OpenMM sees the block whole; cellmd wraps it and takes minimum images).
        for case, n, size, box, periodic in (("random", 4, 3.0, (0.0, 12.0), True), ("small", 2, 1.5, (-10.0, 10.0), False)):
            centre = (0.3, -0.2, 0.1)
            rest, elements = block_mesh(n, size, centre, rng)
            moves = displacements(rest, centre, rng, 0.08)
            # The positions cellmd starts from: rest + move, as f64 sums.
            x = [tuple(p[a] + m[a] for a in range(3)) for p, m in zip(rest, moves)]
            system = system_of(name, p, rest, elements)
            check = energy_numpy(name, p, rest, x, elements)
            context = mm.Context(system, mm.CustomIntegrator(0.0), platform)
            context.setPositions(np.array(x))
            e = context.getState(getEnergy=True, groups={1}).getPotentialEnergy().value_in_unit(mm.unit.kilojoule_per_mole)
            assert abs(e - check) <= 1e-12 * max(abs(check), 1.0), f"{name} {case}: OpenMM {e} vs numpy {check}"
            # The time step: the largest initial force moves its node 0.2 % of a lattice spacing per step.
            f = context.getState(getForces=True).getForces(asNumpy=True).value_in_unit(mm.unit.kilojoule_per_mole / mm.unit.nanometer)
            dt = float(f"{0.002 * (size / n) / np.linalg.norm(f, axis=1).max():.1g}")
            del context
            integrator = mm.CustomIntegrator(dt)
            integrator.addComputePerDof("x", "x + dt*f")
            context = mm.Context(system, integrator, platform)
            context.setPositions(np.array(x))
            init = snapshot(context, name, 0)
            integrator.step(STEPS)
            last = snapshot(context, name, STEPS)
            write_case(name, case, rest, moves, elements, dt, box, periodic)
            header = [
                ("generator", f"OpenMM {mm.__version__} (Reference platform, double precision) via reference/openmm_solids.py"),
                ("date", args.date), ("case", case), ("deck", f"{name}/{case}.in"),
                ("epsilon", "1e-10"), ("run_epsilon", "1e-9"),
                ("epsilon_reason", "OpenMM differentiates the same f64 formulas symbolically (Lepton) and sums in another order; D_m^-1 is inverted by numpy here and by glam in cellmd: measured <= 3.4e-14 relative on every case (tests/suite/golden.rs); 1e-10 leaves margin for other compilers and libm versions"),
                ("run_epsilon_reason", "after 100 overdamped Euler steps (OpenMM CustomIntegrator x <- x + dt*f, drag 1) round-off has accumulated over every step: measured <= 3.2e-13; 1e-9 leaves margin for its growth"),
            ]
            docs.append(document(header, [("init", init), ("run", last)]))
        with open(os.path.join(HERE, f"{name}.yaml.new"), "w") as out:
            out.write("".join(docs))
        print(f"reference/{name}.yaml.new: OpenMM {mm.__version__}, cases random and small")


if __name__ == "__main__":
    main()
