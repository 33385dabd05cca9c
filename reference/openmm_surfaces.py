#!/usr/bin/env python3
"""OpenMM golden data for the surface (`body`) interaction types.

LAMMPS has no many-body surface style, so these types are checked against
OpenMM instead: each energy is written as OpenMM custom-force expressions
(CustomCompoundBondForce over faces or over a node and its ring of
neighbours, CustomCVForce for functions of a body's total volume or area),
OpenMM differentiates them (Lepton) for the forces, and a CustomIntegrator
takes the same deterministic overdamped Euler steps as cellmd at kT = 0,
x <- x + dt*F/gamma, on the Reference platform (double precision).

    python3 reference/openmm_surfaces.py            writes reference/NAME/ (decks and
                                                    topologies) and reference/NAME.yaml.new
    python3 reference/openmm_surfaces.py --list     prints the types it covers

For each type NAME: reference/NAME/NAME.ff, and two cases, each a topology
and an ordinary cellmd deck: `small`, one deformed icosahedron (12 nodes,
fixed box), and `random`, two deformed icospheres of two body types (162
and 42 nodes; periodic box, the first cell across its faces). Deterministic
(fixed seed). `reference/regenerate` runs this script; review with
`diff reference/NAME.yaml reference/NAME.yaml.new`.

The energies are also evaluated here with numpy from cellmd's documented
formulas, and the script stops if OpenMM's expressions disagree: that check
fixes the sign conventions (OpenMM's dihedral) and catches typos; the
forces in the golden files are OpenMM's derivatives of its own expressions.
"""
import argparse
import datetime
import json
import math
import os
import random

import numpy as np
import openmm as mm

HERE = os.path.dirname(os.path.abspath(__file__))
STEPS = 100

# Parameters per body type, per interaction type; `v0`/`a0` as a factor of
# the body's initial volume/area (so the terms act from the first step).
# Parameters of each type's two body types (reference/cases.json, keyed by
# the interaction's name); v0 and a0 are relative to the body's own volume
# and area (body_params).
with open(os.path.join(HERE, "cases.json")) as _f:
    PARAMS = {name: case["params"] for name, case in json.load(_f).items() if case["script"] == "openmm_surfaces.py"}
DRAG = {"a": 1.0, "b": 2.5}


# The geometry is computed in plain Python floats (IEEE, correctly rounded
# sqrt, math.fsum): numpy's BLAS kernels differ by CPU in the last bit, and the
# committed topologies must come out bit-identical on every machine.

def normalised(p):
    n = math.sqrt(math.fsum(c * c for c in p))
    return tuple(c / n for c in p)


def icosphere(level):
    """Unit icosphere: nodes and outward-wound faces (as cellmd::mesh::icosphere)."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    x = [normalised(p) for p in [
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
        (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                x.append(normalised([(p + q) / 2.0 for p, q in zip(x[a], x[b])]))
                mid[key] = len(x) - 1
            return mid[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return x, faces


def rotation(rng):
    """A random rotation: Gram-Schmidt on three Gaussian vectors, the last
    flipped if needed so that the determinant is +1 (a reflection would wind
    the faces inward)."""
    rows = []
    for _ in range(3):
        v = [rng.gauss(0, 1) for _ in range(3)]
        for r in rows:
            d = math.fsum(a * b for a, b in zip(v, r))
            v = [a - d * b for a, b in zip(v, r)]
        rows.append(normalised(v))
    a, b, c = rows
    cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    if math.fsum(x * y for x, y in zip(cross, c)) < 0.0:
        rows[2] = tuple(-x for x in c)
    return rows


def deformed(level, radius, centre, rng):
    """A random ellipsoid-like deformation of the icosphere, rotated, with node jitter."""
    x, faces = icosphere(level)
    axes = [rng.uniform(0.8, 1.25) for _ in range(3)]
    q = rotation(rng)
    pts = []
    for p in x:
        jitter = [rng.gauss(0, 0.06) for _ in range(3)]
        scaled = [c * a for c, a in zip(p, axes)]
        pts.append([radius * (math.fsum(s * r for s, r in zip(scaled, row)) + j) + c0
                    for row, j, c0 in zip(q, jitter, centre)])
    return np.array(pts), faces


def volume_exact(x, faces):
    """Enclosed volume by the divergence theorem, summed with math.fsum."""
    o = [math.fsum(p[k] for p in x) / len(x) for k in range(3)]
    terms = []
    for f in faces:
        a, b, c = ([float(p[k] - o[k]) for k in range(3)] for p in (x[f[0]], x[f[1]], x[f[2]]))
        terms.append(a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]))
    return math.fsum(terms) / 6.0


def area_exact(x, faces):
    """Total surface area, summed with math.fsum."""
    areas = []
    for f in faces:
        a, b, c = ([float(v) for v in x[i]] for i in f)
        u = [b[k] - a[k] for k in range(3)]
        w = [c[k] - a[k] for k in range(3)]
        n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
        areas.append(0.5 * math.sqrt(math.fsum(v * v for v in n)))
    return math.fsum(areas)


# --- the formulas of cellmd, in numpy (the self-check) -----------------------

def face_areas(x, faces):
    f = np.array(faces)
    n = np.cross(x[f[:, 1]] - x[f[:, 0]], x[f[:, 2]] - x[f[:, 0]])
    return 0.5 * np.linalg.norm(n, axis=1)


def volume(x, faces):
    f = np.array(faces)
    o = x.mean(axis=0)
    a, b, c = x[f[:, 0]] - o, x[f[:, 1]] - o, x[f[:, 2]] - o
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


def edges_with_wings(faces):
    directed = {}
    for a, b, c in faces:
        directed[(a, b)] = c
        directed[(b, c)] = a
        directed[(c, a)] = b
    return [(i, j, w, directed[(j, i)]) for (i, j), w in directed.items() if i < j]


def bending_angle(xi, xj, xa, xb):
    e = xj - xi
    na = np.cross(e, xa - xi)
    nb = np.cross(xi - xj, xb - xj)
    return math.atan2(np.dot(np.cross(na, nb), e / np.linalg.norm(e)), np.dot(na, nb))


def turgor_numpy(p, x, faces):
    dv = volume(x, faces) - p["v0"]
    return -p["dp0"] * dv + 0.5 * p["k"] * dv * dv / p["v0"]


def turgor_log_numpy(p, x, faces):
    v = volume(x, faces)
    return -p["dp0"] * (v - p["v0"]) + p["k"] * (v * math.log(v / p["v0"]) - v + p["v0"])


def surface_tension_numpy(p, x, faces):
    return p["gamma"] * face_areas(x, faces).sum()


def area_conservation_numpy(p, x, faces):
    areas = face_areas(x, faces)
    at0 = p["a0"] / len(faces)
    return 0.5 * p["ka"] * (areas.sum() - p["a0"]) ** 2 / p["a0"] + 0.5 * p["kl"] * ((areas - at0) ** 2 / at0).sum()


def surface_shear_numpy(p, x, faces):
    areas = face_areas(x, faces)
    f = np.array(faces)
    a, b, c = x[f[:, 0]], x[f[:, 1]], x[f[:, 2]]
    squares = ((b - a) ** 2).sum(axis=1) + ((c - b) ** 2).sum(axis=1) + ((a - c) ** 2).sum(axis=1)
    return p["k"] * (squares / (4.0 * math.sqrt(3.0) * areas) - 1.0).sum()


def helfrich_bending_numpy(p, x, faces):
    areas = face_areas(x, faces)
    m = np.zeros(len(x))
    a = np.zeros(len(x))
    for i, j, wa, wb in edges_with_wings(faces):
        lt = 0.25 * np.linalg.norm(x[j] - x[i]) * bending_angle(x[i], x[j], x[wa], x[wb])
        m[i] += lt
        m[j] += lt
    for f, area in zip(faces, areas):
        for v in f:
            a[v] += area / 3.0
    u = m - 0.5 * p["c0"] * a
    return (2.0 * p["kappa"] * u * u / a).sum()


# cellmd's documented energy of one body, by interaction name.
ENERGY_NUMPY = {
    "turgor": turgor_numpy,
    "turgor_log": turgor_log_numpy,
    "surface_tension": surface_tension_numpy,
    "area_conservation": area_conservation_numpy,
    "surface_shear": surface_shear_numpy,
    "helfrich_bending": helfrich_bending_numpy,
}


# --- OpenMM expressions -------------------------------------------------------

def cross(p, q, r):
    """Components of (q - p) x (r - p) for particles numbered p, q, r."""
    d = lambda c, s, t: f"({c}{s}-{c}{t})"
    ux, uy, uz = d("x", q, p), d("y", q, p), d("z", q, p)
    vx, vy, vz = d("x", r, p), d("y", r, p), d("z", r, p)
    return f"({uy}*{vz}-{uz}*{vy})", f"({uz}*{vx}-{ux}*{vz})", f"({ux}*{vy}-{uy}*{vx})"


def area_expr(p, q, r):
    nx, ny, nz = cross(p, q, r)
    return f"(0.5*sqrt({nx}^2+{ny}^2+{nz}^2))"


VOLUME_EXPR = ("((x1-cx)*((y2-cy)*(z3-cz)-(z2-cz)*(y3-cy))+(y1-cy)*((z2-cz)*(x3-cx)-(x2-cx)*(z3-cz))"
               "+(z1-cz)*((x2-cx)*(y3-cy)-(y2-cy)*(x3-cx)))/6")


def face_force(expression, params):
    f = mm.CustomCompoundBondForce(3, expression)
    for name in params:
        f.addPerBondParameter(name)
    return f


def ring(faces, i):
    """The neighbours of node i in order: faces (i, r_k, r_k+1) are outward-wound."""
    nxt = {}
    for f in faces:
        if i in f:
            k = f.index(i)
            nxt[f[(k + 1) % 3]] = f[(k + 2) % 3]
    start = min(nxt)
    order = [start]
    while nxt[order[-1]] != start:
        order.append(nxt[order[-1]])
    assert len(order) == len(nxt)
    return order


def helfrich_expr(n):
    """Jülicher's energy of the node (particle 1) with its ring of n neighbours (particles 2..n+1)."""
    r = lambda k: 2 + (k % n)
    parts = ["2*kappa*(M-c*A)^2/A",
             "M=0.25*(" + "+".join(f"l{k}*t{k}" for k in range(n)) + ")",
             "A=(" + "+".join(f"a{k}" for k in range(n)) + ")/3"]
    for k in range(n):
        # Edge (1, r_k), wings r_k+1 (face (1, r_k, r_k+1)) and r_k-1 (face (r_k, 1, r_k-1)).
        parts.append(f"l{k}=distance(p1,p{r(k)})")
        parts.append(f"t{k}=select(step(f{k}),f{k}-{math.pi!r},f{k}+{math.pi!r})")
        parts.append(f"f{k}=dihedral(p{r(k + 1)},p1,p{r(k)},p{r(k - 1)})")
        parts.append(f"a{k}={area_expr(1, r(k), r(k + 1))}")
    return "; ".join(parts)


def per_face_terms(expression, key):
    """An energy that is a sum over faces of one expression with one parameter `key`."""
    def add(system, bodies, group):
        f = face_force(expression, [key])
        for _, _, faces, nodes, p in bodies:
            for a, b, c in faces:
                f.addBond([nodes[a], nodes[b], nodes[c]], [p[key]])
        f.setForceGroup(group)
        system.addForce(f)
    return add


def helfrich_terms(system, bodies, group):
    by_valence = {}
    for _, x, faces, nodes, p in bodies:
        for i in range(len(x)):
            rg = ring(faces, i)
            if len(rg) not in by_valence:
                f = mm.CustomCompoundBondForce(1 + len(rg), helfrich_expr(len(rg)))
                f.addPerBondParameter("kappa")
                f.addPerBondParameter("c")
                f.setForceGroup(group)
                by_valence[len(rg)] = f
            by_valence[len(rg)].addBond([nodes[i]] + [nodes[j] for j in rg], [p["kappa"], 0.5 * p["c0"]])
    for n in sorted(by_valence):
        system.addForce(by_valence[n])


def volume_terms(law):
    """A law of each body's enclosed volume V (CustomCVForce) with global parameters k, dp0, v0."""
    def add(system, bodies, group):
        for _, x, faces, nodes, p in bodies:
            centre = x.mean(axis=0)
            cv = face_force(VOLUME_EXPR, ["cx", "cy", "cz"])
            for a, b, c in faces:
                cv.addBond([nodes[a], nodes[b], nodes[c]], list(centre))
            f = mm.CustomCVForce(law)
            f.addCollectiveVariable("V", cv)
            for key in ("k", "dp0", "v0"):
                f.addGlobalParameter(key, p[key])
            f.setForceGroup(group)
            system.addForce(f)
    return add


def area_conservation_terms(system, bodies, group):
    for _, x, faces, nodes, p in bodies:
        cv = face_force(area_expr(1, 2, 3), [])
        local = face_force(f"0.5*kl*({area_expr(1, 2, 3)}-at0)^2/at0", ["kl", "at0"])
        for a, b, c in faces:
            cv.addBond([nodes[a], nodes[b], nodes[c]], [])
            local.addBond([nodes[a], nodes[b], nodes[c]], [p["kl"], p["a0"] / len(faces)])
        local.setForceGroup(group)
        system.addForce(local)
        f = mm.CustomCVForce("0.5*ka*(A-a0)^2/a0")
        f.addCollectiveVariable("A", cv)
        f.addGlobalParameter("ka", p["ka"])
        f.addGlobalParameter("a0", p["a0"])
        f.setForceGroup(group)
        system.addForce(f)


SHAPE = "(distance(p1,p2)^2+distance(p2,p3)^2+distance(p3,p1)^2)"

# How each interaction's OpenMM forces are added for `bodies` [(type, x, faces, nodes, params)].
OPENMM_TERMS = {
    "turgor": volume_terms("-dp0*(V-v0)+0.5*k*(V-v0)^2/v0"),
    "turgor_log": volume_terms("-dp0*(V-v0)+k*(V*log(V/v0)-V+v0)"),
    "surface_tension": per_face_terms(f"gamma*{area_expr(1, 2, 3)}", "gamma"),
    "area_conservation": area_conservation_terms,
    "surface_shear": per_face_terms(f"k*({SHAPE}/(4*sqrt(3)*{area_expr(1, 2, 3)})-1)", "k"),
    "helfrich_bending": helfrich_terms,
}


def rename_globals(law, suffix, keys):
    for key in sorted(keys, key=len, reverse=True):
        law = law.replace(key, key + suffix)
    return law


def body_params(name, btype, x, faces):
    p = dict(PARAMS[name][btype])
    if "v0" in p:
        p["v0"] = p["v0"] * volume_exact(x, faces)
    if "a0" in p:
        p["a0"] = p["a0"] * area_exact(x, faces)
    return p


def fmt(v):
    return repr(float(v))


def write_case(name, case, bodies, box, periodic, dt):
    """Writes reference/NAME/CASE.top and CASE.in."""
    d = os.path.join(HERE, name)
    lines = [f"# {case} case of {name}: written by reference/openmm_surfaces.py", "[ particles ]"]
    for b, (btype, x, _, nodes, _) in enumerate(bodies):
        for k, pt in enumerate(x):
            ptype = "a" if btype == "cell" else "b"
            lines.append(f"{nodes[k] + 1} {ptype} {fmt(pt[0])} {fmt(pt[1])} {fmt(pt[2])} {b + 1}")
    lines.append("[ bodies ]")
    for b, (btype, *_rest) in enumerate(bodies):
        lines.append(f"{b + 1} {btype}")
    lines.append("[ triangles ]")
    for b, (_, _, faces, nodes, _) in enumerate(bodies):
        for f in faces:
            lines.append(f"{b + 1} {nodes[f[0]] + 1} {nodes[f[1]] + 1} {nodes[f[2]] + 1}")
    with open(os.path.join(d, f"{case}.top"), "w") as out:
        out.write("\n".join(lines) + "\n")
    flag = "p" if periodic else "f"
    deck = (f"units lj\ntopology {case}.top\nforcefield {name}.ff\n"
            f"box x {fmt(box[0])} {fmt(box[1])} {flag} y {fmt(box[0])} {fmt(box[1])} {flag} z {fmt(box[0])} {fmt(box[1])} {flag}\n"
            f"temperature 0\ntimestep {dt}\nthermo 0\nrun {STEPS}\n")
    with open(os.path.join(d, f"{case}.in"), "w") as out:
        out.write(deck)


def openmm_probes(name, bodies):
    """OpenMM's energies, forces, virial and positions at the start and after STEPS steps."""
    n = sum(len(b[1]) for b in bodies)
    system = mm.System()
    gamma = np.zeros(n)
    positions = np.zeros((n, 3))
    for btype, x, faces, nodes, p in bodies:
        for k, pt in enumerate(x):
            positions[nodes[k]] = pt
            gamma[nodes[k]] = DRAG["a" if btype == "cell" else "b"]
    for _ in range(n):
        system.addParticle(1.0)
    OPENMM_TERMS[name](system, bodies, 1)
    # Unique global parameter names per CustomCVForce (one per body).
    for k, f in enumerate(system.getForces()):
        if isinstance(f, mm.CustomCVForce):
            keys = [f.getGlobalParameterName(g) for g in range(f.getNumGlobalParameters())]
            f.setEnergyFunction(rename_globals(f.getEnergyFunction(), f"_{k}", keys))
            for g, key in enumerate(keys):
                f.setGlobalParameterName(g, f"{key}_{k}")
    return system, positions, gamma


def snapshot(context, name, step):
    s = context.getState(getEnergy=True, getForces=True, getPositions=True, groups={1})
    x = s.getPositions(asNumpy=True).value_in_unit(mm.unit.nanometer)
    f = s.getForces(asNumpy=True).value_in_unit(mm.unit.kilojoule_per_mole / mm.unit.nanometer)
    e = s.getPotentialEnergy().value_in_unit(mm.unit.kilojoule_per_mole)
    w = [sum(x[:, a] * f[:, b]) for a, b in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]]
    return dict(step=step, energy=e, energies={name: e}, stress=w, forces=f, positions=x)


def block(rows):
    return "".join(f"  {r}\n" for r in rows)


def document(header, probes):
    out = "---\n" + "".join(f"{k}: {v}\n" for k, v in header)
    for prefix, s in probes:
        out += f"{prefix}_step: {s['step']}\n{prefix}_energy: {fmt(s['energy'])}\n"
        out += f"{prefix}_energies: ! |\n" + block(f"{k} {fmt(v)}" for k, v in s["energies"].items())
        out += f"{prefix}_stress: ! |\n" + block([" ".join(fmt(w) for w in s["stress"])])
        for key in ("forces", "positions"):
            out += f"{prefix}_{key}: ! |\n" + block(f"{k + 1} {fmt(v[0])} {fmt(v[1])} {fmt(v[2])}" for k, v in enumerate(s[key]))
    return out


def case_bodies(name, case, rng):
    if case == "small":
        x, faces = deformed(0, 1.5, (0.3, -0.2, 0.1), rng)
        return [("cell", x, faces, list(range(len(x))), body_params(name, "cell", x, faces))], (-10.0, 10.0), False
    # Two cells in a periodic box of edge 12: the first across the faces x = 0, y = 0 and z = 0.
    x1, f1 = deformed(2, 2.2, (0.4, -0.3, 0.5), rng)
    x2, f2 = deformed(1, 1.6, (6.5, 6.0, 5.5), rng)
    bodies = [("cell", x1, f1, list(range(len(x1))), body_params(name, "cell", x1, f1)),
              ("nucleus", x2, f2, list(range(len(x1), len(x1) + len(x2))), body_params(name, "nucleus", x2, f2))]
    return bodies, (0.0, 12.0), True


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--date", default=datetime.date.today().isoformat())
    args = ap.parse_args()
    if args.list:
        print(" ".join(PARAMS))
        return
    platform = mm.Platform.getPlatformByName("Reference")
    for name in PARAMS:
        rng = random.Random(f"cellmd {name}")
        os.makedirs(os.path.join(HERE, name), exist_ok=True)
        docs = []
        ff = ["particle a drag 1", "particle b drag 2.5"]
        for case in ("random", "small"):
            bodies, box, periodic = case_bodies(name, case, rng)
            system, positions, gamma = openmm_probes(name, bodies)
            # Self-check: OpenMM's expressions against the numpy formulas, per body.
            check = sum(ENERGY_NUMPY[name](p, x, faces) for _, x, faces, _, p in bodies)
            integrator = mm.CustomIntegrator(0.0)
            context = mm.Context(system, integrator, platform)
            context.setPositions(positions)
            e = context.getState(getEnergy=True, groups={1}).getPotentialEnergy().value_in_unit(mm.unit.kilojoule_per_mole)
            assert abs(e - check) <= 1e-12 * max(abs(check), 1.0), f"{name} {case}: OpenMM {e} vs numpy {check}"
            # The time step: the largest initial force moves its node 0.2 % of an edge per step.
            f = context.getState(getForces=True).getForces(asNumpy=True).value_in_unit(mm.unit.kilojoule_per_mole / mm.unit.nanometer)
            edge = min(np.linalg.norm(x[j] - x[i]) for _, x, faces, _, _ in bodies for i, j, _, _ in edges_with_wings(faces))
            dt = float(f"{0.002 * edge * gamma.min() / np.linalg.norm(f, axis=1).max():.1g}")
            del context
            integrator = mm.CustomIntegrator(dt)
            integrator.addPerDofVariable("gamma", 0.0)
            integrator.addComputePerDof("x", "x + dt*f/gamma")
            context = mm.Context(system, integrator, platform)
            context.setPositions(positions)
            integrator.setPerDofVariableByName("gamma", [mm.Vec3(g, g, g) for g in gamma])
            init = snapshot(context, name, 0)
            integrator.step(STEPS)
            last = snapshot(context, name, STEPS)
            write_case(name, case, bodies, box, periodic, dt)
            if case == "random":
                for btype in ("cell", "nucleus"):
                    p = [b[4] for b in bodies if b[0] == btype][0]
                    ff.append(f"body {btype} {name} " + " ".join(f"{k} {fmt(v)}" for k, v in p.items()))
            else:
                # The small case's own force field: the cell's parameters of its own shape.
                small_ff = ["particle a drag 1", f"body cell {name} " + " ".join(f"{k} {fmt(v)}" for k, v in bodies[0][4].items())]
                with open(os.path.join(HERE, name, "small.ff"), "w") as out:
                    out.write("\n".join(small_ff) + "\n")
                with open(os.path.join(HERE, name, "small.in")) as deck:
                    text = deck.read().replace(f"forcefield {name}.ff", "forcefield small.ff")
                with open(os.path.join(HERE, name, "small.in"), "w") as deck:
                    deck.write(text)
            header = [
                ("generator", f"OpenMM {mm.__version__} (Reference platform, double precision) via reference/openmm_surfaces.py"),
                ("date", args.date), ("case", case), ("deck", f"{name}/{case}.in"),
                ("epsilon", "1e-10"), ("run_epsilon", "1e-9"),
                ("epsilon_reason", "OpenMM differentiates the same f64 formulas symbolically (Lepton; CustomCVForce by the chain rule) and sums in another order: measured <= 1.1e-14 relative on every case (tests/suite/golden.rs); 1e-10 leaves margin for other compilers and libm versions"),
                ("run_epsilon_reason", "after 100 overdamped Euler steps (OpenMM CustomIntegrator x <- x + dt*f/gamma) round-off has accumulated over every step (positions relative to the largest displacement, forces and energies to the largest value met): measured <= 1.1e-12; 1e-9 leaves margin for chaotic growth of round-off"),
            ]
            docs.append(document(header, [("init", init), ("run", last)]))
        with open(os.path.join(HERE, name, f"{name}.ff"), "w") as out:
            out.write("\n".join(ff) + "\n")
        with open(os.path.join(HERE, f"{name}.yaml.new"), "w") as out:
            out.write("".join(docs))
        print(f"reference/{name}.yaml.new: OpenMM {mm.__version__}, cases random and small")


if __name__ == "__main__":
    main()
