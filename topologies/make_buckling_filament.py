#!/usr/bin/env python3
"""Writes topologies/buckling_filament.top: a 10 µm microtubule-like filament
of 32 segments along x, bowed by 1 nm at its middle (the seed of the buckling
mode), its first bead a fixed anchor, for inputs/buckling_filament.in.
Deterministic.

    python3 topologies/make_buckling_filament.py
"""
import math
import os

SEGMENTS, LENGTH, BOW = 32, 10.0, 1e-3
here = os.path.dirname(os.path.abspath(__file__))
lines = ["# Written by topologies/make_buckling_filament.py", "[ particles ]"]
for i in range(SEGMENTS + 1):
    kind = "anchor" if i == 0 else "end" if i == SEGMENTS else "bead"
    x = i * LENGTH / SEGMENTS
    y = BOW * math.sin(math.pi * i / SEGMENTS)
    lines.append(f"{i + 1} {kind} {x:.6f} {y:.9f} 0")
lines.append("[ bonds ]")
lines += [f"rod {i} {i + 1}" for i in range(1, SEGMENTS + 1)]
lines.append("[ angles ]")
lines += [f"bend {i} {i + 1} {i + 2}" for i in range(1, SEGMENTS)]
with open(os.path.join(here, "buckling_filament.top"), "w") as f:
    f.write("\n".join(lines) + "\n")
