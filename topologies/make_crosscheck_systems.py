#!/usr/bin/env python3
"""Writes the topologies of the three LAMMPS cross-check example decks
(inputs/bead_spring_network.in, inputs/semiflexible_chains.in,
inputs/walled_cells.in). Deterministic: fixed seeds."""
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "reference"))
from make_systems import unit_vector as unit  # noqa: E402  (one random-direction helper for both)


def mi(d, box):
    return [x - box * round(x / box) for x in d]


def network():
    rng = random.Random(11)
    box, n = 4.0, 200
    pts = []
    while len(pts) < n:
        p = [rng.uniform(0, box) for _ in range(3)]
        if all(math.dist(mi([a - b for a, b in zip(p, q)], box), [0, 0, 0]) > 0.25 for q in pts):
            pts.append(p)
    bonds, degree = [], [0] * n
    for i in range(n):
        near = sorted((math.dist(mi([a - b for a, b in zip(pts[i], pts[j])], box), [0, 0, 0]), j) for j in range(i + 1, n))
        for r, j in near[:3]:
            if r < 0.7 and degree[i] < 4 and degree[j] < 4:
                bonds.append(("short" if r < 0.5 else "long", i + 1, j + 1))
                degree[i] += 1
                degree[j] += 1
    lines = [f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz 0 {box} p\n[ particles ]"]
    lines += [f"{k + 1} {'node' if k % 4 else 'hub'} {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}" for k, p in enumerate(pts)]
    lines += ["[ bonds ]"] + [f"{t} {i} {j}" for t, i, j in bonds]
    return "\n".join(lines) + "\n"


def chains():
    rng = random.Random(5)
    box, n_chains, length = 30.0, 3, 40
    pts, bonds, angles = [], [], []
    for c in range(n_chains):
        while True:
            chain = [[rng.uniform(0, box) for _ in range(3)]]
            d_prev = unit(rng)
            for _ in range(length - 1):
                for _ in range(100):
                    d = unit(rng)
                    if sum(a * b for a, b in zip(d, d_prev)) > 0.3:
                        break
                q = [a + 1.0 * b for a, b in zip(chain[-1], d)]
                chain.append(q)
                d_prev = d
            others = pts + chain
            if all(math.dist(mi([a - b for a, b in zip(others[i], others[j])], box), [0, 0, 0]) > 0.9
                   for i in range(len(others)) for j in range(i + 2, len(others))):
                break
        base = len(pts)
        pts += chain
        bonds += [(base + k + 1, base + k + 2) for k in range(length - 1)]
        angles += [(base + k + 1, base + k + 2, base + k + 3) for k in range(length - 2)]
    lines = [f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz 0 {box} p\n[ particles ]"]
    lines += [f"{k + 1} bead {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}" for k, p in enumerate(pts)]
    lines += ["[ bonds ]"] + [f"backbone {i} {j}" for i, j in bonds]
    lines += ["[ angles ]"] + [f"stiff {i} {j} {k}" for i, j, k in angles]
    return "\n".join(lines) + "\n"


def cells():
    rng = random.Random(3)
    box = 6.0
    lines = [f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz -1 5 f\n[ particles ]"]
    bonds, pid = [], 0
    for cx in range(3):
        for cy in range(3):
            centre = [1.0 + 2.0 * cx + rng.uniform(-0.2, 0.2), 1.0 + 2.0 * cy + rng.uniform(-0.2, 0.2), 0.45]
            pid += 1
            c = pid
            lines.append(f"{c} nucleus {centre[0]:.6f} {centre[1]:.6f} {centre[2]:.6f}")
            for k in range(6):
                a = 2 * math.pi * k / 6 + rng.uniform(-0.1, 0.1)
                pid += 1
                z = centre[2] - 0.4 + rng.uniform(-0.05, 0.05)
                lines.append(f"{pid} cortex {centre[0] + 0.6 * math.cos(a):.6f} {centre[1] + 0.6 * math.sin(a):.6f} {z:.6f}")
                bonds.append(("spoke", c, pid))
                bonds.append(("rim", pid, c + 1 + (k + 1) % 6))
    lines += ["[ bonds ]"] + [f"{t} {i} {j}" for t, i, j in bonds]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    for name, text in [("bead_spring_network.top", network()), ("semiflexible_chains.top", chains()), ("walled_cells.top", cells())]:
        with open(os.path.join(HERE, name), "w") as f:
            f.write(text)
