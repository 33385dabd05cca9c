#!/usr/bin/env python3
"""Writes the reference systems: for each interaction type NAME,
reference/NAME/NAME.ff and two cases, `small` (1-3 particles) and `random`
(>= 100 particles, periodic where the type allows, with images, exclusions
and two particle types exercised), each a topology and an ordinary cellmd deck
in `units lj`. Likewise for the bond kinetics LAMMPS can express:
reference/threshold (deterministic strain threshold = fix bond/break) and
reference/bind (certain mutual-nearest binding = fix bond/create), on frozen
particles (see kinetics()). Deterministic (fixed seeds); rerun only to change
the systems, then `reference/regenerate` to record LAMMPS' answers.
Likewise reference/per_bond_r0: bonds with their own rest lengths, which the
export writes as one LAMMPS bond type per distinct (type, r0).
Likewise reference/custom: `custom` expressions as LAMMPS lepton styles.
The per-type choices of the bond, angle and pair cases (force-field lines,
time step, small system) are data in reference/cases.json, keyed by the
interaction's name beside the surface and volume types' parameters.
"""
import json
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))

# The case of each interaction type, keyed by its name (reference/cases.json,
# entries whose "script" is this file): its force-field lines, time step and
# the 3-particle `small` system; bonds and angles also give the range of the
# random chains' segment lengths, pairs the minimum distance between particles.
with open(os.path.join(HERE, "cases.json")) as _f:
    CASES = {name: case for name, case in json.load(_f).items() if case["script"] == "make_systems.py"}
TYPES = "particle a drag 1\nparticle b drag 2.5\n"


def fmt(x):
    return repr(round(x, 6))


def unit_vector(rng):
    while True:
        v = [rng.uniform(-1, 1) for _ in range(3)]
        n = math.sqrt(sum(c * c for c in v))
        if 0.1 < n <= 1:
            return [c / n for c in v]


def particles_block(points, types):
    lines = ["[ particles ]"]
    for k, (p, t) in enumerate(zip(points, types)):
        lines.append(f"{k + 1} {t} {fmt(p[0])} {fmt(p[1])} {fmt(p[2])}")
    return "\n".join(lines) + "\n"


def chains(rng, n_chains, length, step, lo, box, bend_max=None):
    """Random walks with segment lengths in [lo, hi]; unwrapped coordinates."""
    points = []
    for _ in range(n_chains):
        p = [rng.uniform(0, box) for _ in range(3)]
        previous = None
        for _ in range(length):
            points.append(p)
            while True:
                d = unit_vector(rng)
                if previous is None or bend_max is None:
                    break
                cos = sum(a * b for a, b in zip(d, previous))
                if cos > math.cos(math.radians(bend_max)):
                    break
            previous = d
            r = rng.uniform(lo, step)
            p = [a + r * b for a, b in zip(p, d)]
    return points


def deck(top, ff, box, dt, steps=100, extra=""):
    return (f"units lj\ntopology {top}\nforcefield {ff}\nbox {box}\n{extra}"
            f"temperature 0\ntimestep {dt}\nthermo 0\nrun {steps}\n")


def write(name, files):
    d = os.path.join(HERE, name)
    os.makedirs(d, exist_ok=True)
    for fname, text in files.items():
        with open(os.path.join(d, fname), "w") as f:
            f.write(text)


def forcefield(case):
    return "".join(line + "\n" for line in case["forcefield"])


def bonded(name, case):
    kind = case["kind"]
    rng = random.Random(sum(map(ord, name)))
    lo, hi = case["segment"]
    # small: a 3-particle chain, one bond stretched and one compressed (angle: one angle)
    small = case["small"]
    top = particles_block(small, ["a", "b", "a"])
    top += "[ bonds ]\ns 1 2\nt 2 3\n" if kind == "bond" else "[ angles ]\ns 1 2 3\n"
    n_chains, length, box = 12, 10, 6.0
    pts = chains(rng, n_chains, length, hi, lo, box, bend_max=120 if kind == "angle" else None)
    types = ["a" if (k // length) % 3 else "b" for k in range(len(pts))]
    rtop = f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz 0 {box} p\n" + particles_block(pts, types)
    if kind == "bond":
        rtop += "[ bonds ]\n" + "".join(f"{'s' if k % 2 else 't'} {c * length + k + 1} {c * length + k + 2}\n" for c in range(n_chains) for k in range(length - 1))
    else:
        rtop += "[ angles ]\n" + "".join(f"{'s' if k % 2 else 't'} {c * length + k + 1} {c * length + k + 2} {c * length + k + 3}\n" for c in range(n_chains) for k in range(length - 2))
    dt = case["dt"]
    write(name, {
        f"{name}.ff": TYPES + forcefield(case),
        "small.top": top,
        "random.top": rtop,
        "small.in": deck("small.top", f"{name}.ff", "x -5 5 f y -5 5 f z -5 5 f", dt),
        "random.in": deck("random.top", f"{name}.ff", f"x 0 {box} p y 0 {box} p z 0 {box} p", dt),
    })


def pairs(name, case):
    rng = random.Random(sum(map(ord, name)))
    dmin = case["min_distance"]
    box, n = 6.5, 150
    pts = []
    # chains of 5 bonded beads (exclusions), placed with a minimum distance
    while len(pts) < n:
        p = [rng.uniform(0, box) for _ in range(3)] if len(pts) % 5 == 0 else [a + 1.0 * b for a, b in zip(pts[-1], unit_vector(rng))]
        ok = all(math.dist(min_image(p, q, box), [0, 0, 0]) > dmin for q in pts)
        if ok:
            pts.append(p)
        elif len(pts) % 5:
            del pts[-(len(pts) % 5):]
    types = ["b" if k % 3 == 0 else "a" for k in range(n)]
    rtop = particles_block(pts, types) + "[ bonds ]\n" + "".join(f"s {c * 5 + k + 1} {c * 5 + k + 2}\n" for c in range(n // 5) for k in range(4))
    stop = particles_block(case["small"], ["a", "a", "b"])
    dt = case["dt"]
    write(name, {
        f"{name}.ff": TYPES + "bond s harmonic k 20 r0 1.0\n" + forcefield(case),
        "small.top": stop,
        "random.top": rtop,
        "small.in": deck("small.top", f"{name}.ff", "x -5 5 f y -5 5 f z -5 5 f", dt),
        "random.in": deck("random.top", f"{name}.ff", f"x 0 {box} p y 0 {box} p z 0 {box} p", dt),
    })


def min_image(p, q, box):
    return [(a - b) - box * round((a - b) / box) for a, b in zip(p, q)]


def externals():
    rng = random.Random(7)
    box = 5.0
    # wall: a floor on everything, a ceiling on type b; periodic in x and y
    pts = [[rng.uniform(0, box), rng.uniform(0, box), rng.uniform(-0.5, 4.6)] for _ in range(100)]
    types = ["b" if k % 2 else "a" for k in range(100)]
    walls = ("group bs type b\nexternal floor all wall nz 1 d 0 k 20\n"
             "external ceiling bs wall nz -2 d -4 k 30\nexternal side all wall nx 1 nz 0 d 0.5 k 5\n")
    small_walls = "external floor all wall nz 1 d 0 k 20\nexternal ceiling all wall ny -1 nz 0 d -1 k 30\n"
    write("wall", {
        "wall.ff": TYPES,
        "small.top": particles_block([[0.3, 0.2, -0.25], [0.1, 1.2, 0.5]], ["a", "b"]),
        "random.top": particles_block(pts, types),
        "small.in": deck("small.top", "wall.ff", "x -5 5 f y -5 5 f z -5 5 f", 1e-3, extra=small_walls),
        "random.in": deck("random.top", "wall.ff", f"x 0 {box} f y 0 {box} p z -1 5 f", 1e-3, extra=walls),
    })
    # constant_force: chains in a periodic box dragged across its faces
    pts = chains(rng, 10, 10, 1.2, 0.8, box)
    types = ["b" if (k // 10) % 2 else "a" for k in range(100)]
    rtop = particles_block(pts, types) + "[ bonds ]\n" + "".join(f"s {c * 10 + k + 1} {c * 10 + k + 2}\n" for c in range(10) for k in range(9))
    pull = ("group as type a\ngroup head id 1:20\nexternal drift as constant_force fx 2.5 fy -1.5 fz 1\n"
            "external pull head constant_force fz 3\n")
    write("constant_force", {
        "constant_force.ff": TYPES + "bond s harmonic k 20 r0 1.0\n",
        "small.top": particles_block([[0.3, 0.2, 0.1], [1.1, -0.4, 2.0]], ["a", "b"]),
        "random.top": rtop,
        "small.in": deck("small.top", "constant_force.ff", "x -5 5 f y -5 5 f z -5 5 f", 1e-2,
                         extra="external pull all constant_force fx 0.5 fy -0.25 fz 2\n"),
        "random.in": deck("random.top", "constant_force.ff", f"x 0 {box} p y 0 {box} p z 0 {box} p", 1e-2, extra=pull),
    })


def indenter():
    """Spherical indenters (LAMMPS fix indent sphere) pressed into a slab."""
    rng = random.Random(11)
    box = 5.0
    pts = [[rng.uniform(0, box), rng.uniform(0, box), rng.uniform(0, 3.0)] for _ in range(100)]
    types = ["b" if k % 2 else "a" for k in range(100)]
    tips = ("group bs type b\nexternal tip all indenter x 2.5 y 2.5 z 4.5 r 2 k 10\n"
            "external bead bs indenter x 2.5 y 2.5 z -0.5 r 1.5 k 30\n")
    write("indenter", {
        "indenter.ff": TYPES,
        "small.top": particles_block([[0.3, 0.2, 0.25], [0.1, 1.2, 1.5]], ["a", "b"]),
        "random.top": particles_block(pts, types),
        "small.in": deck("small.top", "indenter.ff", "x -5 5 f y -5 5 f z -5 5 f", 1e-3,
                         extra="external tip all indenter x 0 y 0 z 2 r 2 k 20\n"),
        # Periodic, with the spheres within half a box of every particle: LAMMPS
        # takes the minimum image of x − c, cellmd the unwrapped x (the same here).
        "random.in": deck("random.top", "indenter.ff", f"x 0 {box} p y 0 {box} p z 0 10 p", 1e-3, extra=tips),
    })


def random_points(rng, n, box, dmin):
    """n points in a periodic cube, no two closer than dmin."""
    pts = []
    while len(pts) < n:
        p = [rng.uniform(0, box) for _ in range(3)]
        if all(math.dist(min_image(p, q, box), [0, 0, 0]) > dmin for q in pts):
            pts.append([round(c, 6) for c in p])
    return pts


def pair_distances(pts, box):
    n = len(pts)
    return {(i, j): math.dist(min_image(pts[i], pts[j], box), [0, 0, 0]) for i in range(n) for j in range(i + 1, n)}


KINETIC_TYPES = "particle a fixed\nparticle b fixed\n"


def kinetics():
    """Frozen random networks (every particle type `fixed`, as LAMMPS atoms with
    no integrator): only the bond kinetics change the system, so the final bond
    sets of both engines must agree although LAMMPS decides per step
    differently (see README, *Checking against LAMMPS*)."""
    # threshold: bonds of types s (r0 1, breaks beyond 1.2) and t (r0 1.1,
    # beyond 1.265) at random lengths on both sides of their threshold, never
    # compressed beyond it (cellmd breaks those too; LAMMPS only stretched
    # ones); bonds of type u never break. Many particles carry several
    # over-threshold bonds, which LAMMPS breaks one per step.
    rng = random.Random(51)
    box, n = 6.0, 150
    pts = random_points(rng, n, box, 0.7)
    types = ["b" if k % 3 == 0 else "a" for k in range(n)]
    d = pair_distances(pts, box)
    law = {"s": (1.0, 0.2, 0.85, 1.5), "t": (1.1, 0.15, 0.96, 1.55), "u": (1.2, None, 0.8, 1.6)}
    degree = [0] * n
    bonds = []
    pairs = sorted(d)
    rng.shuffle(pairs)
    for (i, j) in pairs:
        if degree[i] >= 5 or degree[j] >= 5:
            continue
        name = rng.choice("sstu")
        r0, strain, lo, hi = law[name]
        if not lo <= d[i, j] <= hi:
            continue
        if strain is not None and abs(d[i, j] - r0 * (1 + strain)) < 1e-3:
            continue
        bonds.append((name, i, j))
        degree[i] += 1
        degree[j] += 1
    ff = (KINETIC_TYPES
          + "bond s harmonic k 50 r0 1.0 kinetics threshold strain 0.2\n"
          + "bond t spring k 30 r0 1.1 tau 0.05 kinetics threshold strain 0.15\n"
          + "bond u harmonic k 20 r0 1.2\n"
          # Broken bonds stop excluding their pair: these energies follow the exclusions.
          + "pair a a soft_repulsion k 20 sigma 1.0\npair a b soft_repulsion k 5 sigma 1.6\n")
    rtop = f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz 0 {box} p\n" + particles_block(pts, types)
    rtop += "[ bonds ]\n" + "".join(f"{t} {i + 1} {j + 1}\n" for t, i, j in bonds)
    # small: a chain 1.5, 1.3, 1.1 long: LAMMPS breaks 1-2 (the longest) in
    # its first step and 2-3 in its second; 3-4 stays.
    small = [[0, 0, 0], [1.5, 0, 0], [1.5, 1.3, 0], [1.5, 1.3, 1.1]]
    stop = particles_block(small, ["a", "a", "b", "a"]) + "[ bonds ]\ns 1 2\ns 2 3\ns 3 4\n"
    write("threshold", {
        "threshold.ff": ff,
        "small.top": stop,
        "random.top": rtop,
        "small.in": deck("small.top", "threshold.ff", "x -5 5 f y -5 5 f z -5 5 f", 0.01, steps=5),
        "random.in": deck("random.top", "threshold.ff", f"x 0 {box} p y 0 {box} p z 0 {box} p", 0.01, steps=20),
    })

    # bind: a-b pairs closer than 1.0 form `link` bonds (at most 2 per
    # particle, counting the topology's links), b-b pairs closer than 0.8
    # form `glue` bonds (at most 1), each particle with its nearest free
    # partner when that choice is mutual. `s` bonds join a-a pairs only, so no
    # bindable pair is already bonded by another type (LAMMPS would refuse it).
    rng = random.Random(52)
    box, n = 6.5, 160
    pts = random_points(rng, n, box, 0.45)
    types = ["a" if k % 2 else "b" for k in range(n)]
    d = pair_distances(pts, box)
    capture = {("a", "b"): 1.0, ("b", "b"): 0.8}
    near = sorted(v for (i, j), v in d.items() if (tuple(sorted((types[i], types[j]))) in capture))
    assert all(b - a > 1e-9 for a, b in zip(near, near[1:])), "tied distances"
    assert all(abs(v - capture[tuple(sorted((types[i], types[j])))]) > 1e-6
               for (i, j), v in d.items() if tuple(sorted((types[i], types[j]))) in capture)
    pairs = sorted(d)
    rng.shuffle(pairs)
    links, chains = [], []
    used = [0] * n
    for (i, j) in pairs:
        kind = "".join(sorted((types[i], types[j])))
        if kind == "ab" and d[i, j] < 1.2 and used[i] < 1 and used[j] < 1 and len(links) < 12:
            links.append((i, j))
        elif kind == "aa" and d[i, j] < 1.3 and used[i] < 2 and used[j] < 2 and len(chains) < 30:
            chains.append((i, j))
        else:
            continue
        used[i] += 1
        used[j] += 1
    ff = (KINETIC_TYPES
          + "bond s harmonic k 20 r0 1.0\nbond link harmonic k 10 r0 0.8\nbond glue harmonic k 40 r0 0.5\n"
          + "bind a b link k_on 1e9 capture 1.0 max_bonds 2 partner nearest\n"
          + "bind b b glue k_on 1e9 capture 0.8 max_bonds 1 partner nearest\n"
          # Formed bonds exclude their pair: this energy follows the exclusions.
          + "pair a b soft_repulsion k 10 sigma 0.7\n")
    rtop = f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz 0 {box} p\n" + particles_block(pts, types)
    rtop += "[ bonds ]\n" + "".join(f"link {i + 1} {j + 1}\n" for i, j in links) + "".join(f"s {i + 1} {j + 1}\n" for i, j in chains)
    # small: a at 0, b at 0.6 and 0.9 on a line, all b: the pair 0.3 apart
    # binds first, then 1-2 (0.6), then 1-3 (0.9), one bond per particle and step.
    small = [[0.0, 0.0, 0.0], [0.6, 0.0, 0.0], [0.9, 0.0, 0.0]]
    sff = KINETIC_TYPES + "bond link harmonic k 10 r0 0.8\nbind b b link k_on 1e9 capture 1.0 max_bonds 2 partner nearest\n"
    write("bind", {
        "bind.ff": ff,
        "small.ff": sff,
        "small.top": particles_block(small, ["b", "b", "b"]),
        "random.top": rtop,
        "small.in": deck("small.top", "small.ff", "x -5 5 f y -5 5 f z -5 5 f", 0.01, steps=5),
        "random.in": deck("random.top", "bind.ff", f"x 0 {box} p y 0 {box} p z 0 {box} p", 0.01, steps=10),
    })


def per_bond_r0():
    """Bonds with their own rest lengths (`type i j r0` in the topology): the
    four bond laws with an r0, most bonds at their own r0 (0.8-1.2 of their
    length as placed, so all are loaded), some at the type's r0 (no field),
    some giving exactly the type's r0 (the export keeps those on the type's
    LAMMPS bond type); the export makes one LAMMPS bond type per other
    distinct (type, r0)."""
    rng = random.Random(53)
    laws = {"h": 1.0, "c": 1.0, "s": 0.9, "a": 1.0}
    ff = (TYPES + "bond h harmonic k 50 r0 1.0\nbond c cable k 40 r0 1.0 tau 0.05\n"
          + "bond s spring k 30 r0 0.9 tau -0.05\nbond a asymmetric k_tension 60 k_compression 15 r0 1.0\n")
    n_chains, length, box = 12, 10, 6.0
    pts = chains(rng, n_chains, length, 1.3, 0.7, box)
    types = ["a" if (k // length) % 3 else "b" for k in range(len(pts))]
    lines = []
    for c in range(n_chains):
        for k in range(length - 1):
            i, j = c * length + k, c * length + k + 1
            name = "hcsa"[(c + k) % 4]
            r = math.dist(pts[i], pts[j])
            if k % 4 == 3:
                lines.append(f"{name} {i + 1} {j + 1}\n")
            elif k % 4 == 2 and c % 2:
                lines.append(f"{name} {i + 1} {j + 1} {laws[name]!r}\n")
            else:
                lines.append(f"{name} {i + 1} {j + 1} {fmt(r * rng.uniform(0.8, 1.2))}\n")
    rtop = f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz 0 {box} p\n" + particles_block(pts, types) + "[ bonds ]\n" + "".join(lines)
    small = [[0.1, 0.2, 0.3], [1.2, 0.5, 0.1], [1.7, 1.2, 0.6], [2.4, 0.9, 1.5]]
    stop = particles_block(small, ["a", "b", "a", "b"]) + "[ bonds ]\nh 1 2 0.9\nh 2 3\nc 3 4 1.1\n"
    write("per_bond_r0", {
        "per_bond_r0.ff": ff,
        "small.top": stop,
        "random.top": rtop,
        "small.in": deck("small.top", "per_bond_r0.ff", "x -5 5 f y -5 5 f z -5 5 f", 1e-3),
        "random.in": deck("random.top", "per_bond_r0.ff", f"x 0 {box} p y 0 {box} p z 0 {box} p", 1e-3),
    })


def custom():
    """`custom` expressions of every kind LAMMPS expresses (lepton bond,
    angle and pair styles; fix addforce for an external): restatements of
    harmonic, cosine_angle, harmonic_angle and soft, and laws no built-in has,
    on bonded chains with angles and two particle types."""
    rng = random.Random(sum(map(ord, "custom")))
    ff = (TYPES
          + 'bond s custom "0.5*k*(r-r0)^2" k 50 r0 1.0\n'
          + 'bond t custom "k*(r-r0)^2 + c*(r-r0)^3" k 40 r0 0.9 c 5\n'
          + 'angle s custom "K*(1+cos(theta))" K 2\n'
          + 'angle t custom "0.5*k*(theta-theta0)^2" k 3 theta0 110deg\n'
          + 'pair a a custom "A*(1+cos(pi*r/rc))" cutoff 1.0 A 5 rc 1.0\n'
          + 'pair a b custom "eps*(1-r/rc)^2*exp(-r)" cutoff 1.2 eps 3 rc 1.2\n'
          + 'pair b b custom "A*(1+cos(pi*r/rc))" cutoff 1.1 A 8 rc 1.1\n')
    small = [[0.1, 0.2, 0.3], [1.2, 0.5, 0.1], [1.7, 1.2, 0.6], [0.9, 1.1, 0.2]]
    top = particles_block(small, ["a", "b", "a", "b"]) + "[ bonds ]\ns 1 2\nt 2 3\n[ angles ]\nt 1 2 3\n"
    n_chains, length, box = 12, 10, 6.0
    pts = chains(rng, n_chains, length, 1.3, 0.7, box, bend_max=120)
    types = ["a" if (k // length) % 3 else "b" for k in range(len(pts))]
    rtop = f"[ box ]\nx 0 {box} p\ny 0 {box} p\nz 0 {box} p\n" + particles_block(pts, types)
    rtop += "[ bonds ]\n" + "".join(f"{'s' if k % 2 else 't'} {c * length + k + 1} {c * length + k + 2}\n" for c in range(n_chains) for k in range(length - 1))
    rtop += "[ angles ]\n" + "".join(f"{'t' if k % 2 else 's'} {c * length + k + 1} {c * length + k + 2} {c * length + k + 3}\n" for c in range(n_chains) for k in range(length - 2))
    write("custom", {
        "custom.ff": ff,
        "small.top": top,
        "random.top": rtop,
        # A custom external (fix addforce with −∇E from the symbolic derivatives).
        "small.in": deck("small.top", "custom.ff", "x -5 5 f y -5 5 f z -5 5 f", 1e-3,
                         extra='external trap all custom "0.5*k*((x-x0)^2+y^2)+f*z*exp(-z^2)" k 3 x0 0.5 f 0.7\n'),
        "random.in": deck("random.top", "custom.ff", f"x 0 {box} p y 0 {box} p z 0 {box} p", 1e-3),
    })


if __name__ == "__main__":
    for name, case in CASES.items():
        (pairs if case["kind"] == "pair" else bonded)(name, case)
    externals()
    indenter()
    kinetics()
    per_bond_r0()
    custom()
