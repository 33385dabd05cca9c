#!/usr/bin/env python3
"""Writes the topologies of the bond-kinetics example decks (µm; deterministic).

    python3 topologies/make_kinetics_examples.py

- catch_slip_sweep.top: 8 groups of 400 pairs of fixed particles; the pairs of
  group g are 0.05 + F_g/k apart, so their harmonic bond (k = 1000 pN/µm,
  r0 = 0.05 µm) carries F_g = 0, 4, …, 28 pN. Bond types pulled_<F>pN.
- clutch.top: a 4 µm actin bundle (41 beads) above 80 fixed substrate anchors,
  one integrin clutch from every other bead to the anchor below it.
- fibre_bundle.top: 1000 parallel fibres from fixed anchors to a single load
  plate particle, so every intact fibre carries the same strain (equal load
  sharing, as in Daniels' bundle).
"""
FORCES = [4 * g for g in range(8)]


def sweep():
    lines = ["# Catch-slip lifetime sweep: fixed pairs under constant force (make_kinetics_examples.py)", "[ particles ]"]
    bonds = ["[ bonds ]"]
    pid = 0
    for g, f in enumerate(FORCES):
        length = 0.05 + f / 1000.0
        for p in range(400):
            x, y = 0.5 * (p % 20), 0.5 * (p // 20) + 12.0 * g
            lines.append(f"{pid + 1} anchor {x:.3f} {y:.3f} 0")
            lines.append(f"{pid + 2} anchor {x:.3f} {y:.3f} {length:.6f}")
            bonds.append(f"pulled_{f}pN {pid + 1} {pid + 2}")
            pid += 2
    return "\n".join(lines + bonds) + "\n"


def clutch():
    lines = ["# Actin bundle on integrin clutches over a substrate (make_kinetics_examples.py)", "[ particles ]"]
    bonds, angles = ["[ bonds ]"], ["[ angles ]"]
    beads = 41
    for b in range(beads):
        lines.append(f"{b + 1} actin {0.1 * b:.3f} 0 0.05")
    for a in range(80):
        lines.append(f"{beads + a + 1} site {0.05 * a:.3f} 0 0")
    for b in range(beads - 1):
        bonds.append(f"actin_segment {b + 1} {b + 2}")
    for b in range(beads - 2):
        angles.append(f"actin_bend {b + 1} {b + 2} {b + 3}")
    for b in range(0, beads, 2):
        anchor = min(2 * b, 79)
        bonds.append(f"clutch {b + 1} {beads + anchor + 1}")
    return "\n".join(lines + bonds + angles) + "\n"


def bundle():
    lines = ["# Fibre bundle: fibres from fixed anchors to one load plate (make_kinetics_examples.py)", "[ particles ]"]
    bonds = ["[ bonds ]"]
    n = 1000
    lines.append(f"{n + 1} plate 0 0 1")
    for f in range(n):
        lines.append(f"{f + 1} anchor 0 0 0")
        bonds.append(f"fibre {f + 1} {n + 1}")
    return "\n".join(lines + bonds) + "\n"


for name, text in [("catch_slip_sweep", sweep()), ("clutch", clutch()), ("fibre_bundle", bundle())]:
    with open(f"topologies/{name}.top", "w") as out:
        out.write(text)
