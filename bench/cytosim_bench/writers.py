"""Writes one `System` for both engines: a Cytosim config (.cym) and a cellmd
topology, force field and deck.

The two models are the same physics term by term:

| physics | Cytosim (2017) | cellmd |
|---|---|---|
| inextensible segments of length ℓ | `fiber` (constrained by projection) | bonds `seg` held by `constrain seg`, or stiff `harmonic` springs (the springs variants) |
| bending, E = (κ/ℓ)(1 − t·t') per joint | `rigidity = κ` | angles `bend` with `wlc_bending kappa κ l0 ℓ` |
| drag γ = ζ/n per point | from `viscosity` and `hydrodynamic_radius` | `particle bead drag γ` (the same number) |
| a clamped point | `single` of `activity = fixed`, stiffness `clamp_stiffness` | a `fixed` particle |
| a constant force F on a point | a `fixed` single of stiffness \\|F\\|/D anchored D = `load_distance` away along F (the force varies by the point's travel over D, ≤ 1e-3) | `external … constant_force` |
| a crosslink between two points | `couple` (zero rest length, Hookean) attached at both abscissae | bond `link`, `harmonic … r0 0` |

Every `new` says `placement = anywhere`: by default Cytosim places an object
only inside its space and silently creates none when it cannot (a load's
anchor lies far outside). Cytosim numbers its fibres from 1 in creation order; an attachment at
abscissa s = i·ℓ lies on point i (hands interpolate between points, and
at a point the interpolation is that point).
"""

import os

from .systems import System

VARIANTS = {
    "constrained-explicit": ("overdamped", True),
    "constrained-implicit": ("implicit", True),
    "springs-explicit": ("overdamped", False),
    "springs-implicit": ("implicit", False),
}


def fmt(value):
    return repr(float(value))


def vec(values):
    return " ".join(fmt(v) for v in values)


def extent(system: System, margin=20.0):
    """Bounds (lo, hi) of the fibres' initial points, widened by `margin` µm."""
    points = [system.point(f, p) for f in range(len(system.fibres)) for p in range(system.points)]
    lo = [min(p[k] for p in points) - margin for k in range(3)]
    hi = [max(p[k] for p in points) + margin for k in range(3)]
    return lo, hi


def half_extent(system: System):
    lo, hi = extent(system)
    return [max(abs(a), abs(b)) for a, b in zip(lo, hi)]


# --------------------------------------------------------------------- Cytosim


def cytosim_config(system: System, dt, precondition):
    """The .cym text of `system` at time step `dt` with `precondition` 0 or 1."""
    frames = round(system.time / system.frame)
    out = [
        f"% {system.label}: written by bench/cytosim from its description of the system",
        "set simul system",
        "{",
        f"    time_step = {fmt(dt)}",
        f"    viscosity = {fmt(system.viscosity)}",
        f"    kT = {fmt(system.kT)}",
        f"    precondition = {precondition}",
        "    tolerance = 0.05",
        f"    random_seed = {system.seed}",
        "}",
        "",
        "% Cytosim needs a space; no fibre is confined by it",
        "set space cell",
        "{",
        f"    geometry = rectangle {vec(half_extent(system))}",
        "}",
        "new space cell",
        "",
        "set fiber filament",
        "{",
        f"    rigidity = {fmt(system.rigidity)}",
        f"    segmentation = {fmt(system.segmentation)}",
        f"    hydrodynamic_radius = {fmt(system.radius)}, {fmt(system.cutoff)}",
        "}",
        "",
    ]
    for start, direction in system.fibres:
        centre = [s + 0.5 * system.length * d for s, d in zip(start, direction)]
        out.append(f"new fiber filament {{ length = {fmt(system.length)}; position = {vec(centre)}; direction = {vec(direction)}; placement = anywhere }}")
    if system.clamps or system.loads or system.links:
        out += ["", "set hand holder", "{", "    binding = 0, 0", "    unbinding = 0, inf", "}"]
    if system.clamps:
        out += ["", "set single clamp", "{", "    hand = holder", f"    stiffness = {fmt(system.clamp_stiffness)}", "    activity = fixed", "}"]
        for fibre, point in system.clamps:
            out.append(f"new single clamp {{ position = {vec(system.point(fibre, point))}; attach = {fibre + 1}, {fmt(point * system.segmentation)}; placement = anywhere }}")
    for n, (fibre, point, force) in enumerate(system.loads):
        magnitude = sum(f * f for f in force) ** 0.5
        anchor = [x + system.load_distance * f / magnitude for x, f in zip(system.point(fibre, point), force)]
        out += ["", f"set single load{n}", "{", "    hand = holder", f"    stiffness = {fmt(magnitude / system.load_distance)}", "    activity = fixed", "}"]
        out.append(f"new single load{n} {{ position = {vec(anchor)}; attach = {fibre + 1}, {fmt(point * system.segmentation)}; placement = anywhere }}")
    if system.links:
        out += ["", "set couple link", "{", "    hand1 = holder", "    hand2 = holder", f"    stiffness = {fmt(system.link_stiffness)}", "}"]
        for a, i, b, j in system.links:
            out.append(f"new couple link {{ attach1 = {a + 1}, {fmt(i * system.segmentation)}; attach2 = {b + 1}, {fmt(j * system.segmentation)}; placement = anywhere }}")
    out += ["", f"run {system.steps(dt)} simul *", "{", f"    nb_frames = {frames}", "}", ""]
    return "\n".join(out)


# ---------------------------------------------------------------------- cellmd


def point_id(system, fibre, point):
    return fibre * system.points + point + 1


def fibre_drag(system: System):
    """The force-field lines that give each free fibre point its drag.

    Today: Cytosim's per-point drag computed here. When cellmd computes fibre
    drag itself this becomes `["particle bead fibre", f"fibre filament bond seg
    radius {system.radius} viscosity {system.viscosity}"]`.
    """
    return [f"particle bead drag {fmt(system.point_drag())}   # ζ/n, ζ = {system.drag():.6g} pN·s/µm (Cytosim's formula)"]


def cellmd_topology(system: System):
    clamped = set(system.clamps)
    out = [f"# {system.label}: written by bench/cytosim", "[ particles ]"]
    for f in range(len(system.fibres)):
        for p in range(system.points):
            kind = "clamp" if (f, p) in clamped else "bead"
            out.append(f"{point_id(system, f, p)} {kind} {vec(system.point(f, p))}")
    out.append("[ bonds ]")
    for f in range(len(system.fibres)):
        for p in range(system.segments):
            out.append(f"seg {point_id(system, f, p)} {point_id(system, f, p + 1)}")
    for a, i, b, j in system.links:
        out.append(f"link {point_id(system, a, i)} {point_id(system, b, j)}")
    out.append("[ angles ]")
    for f in range(len(system.fibres)):
        for p in range(system.segments - 1):
            out.append(f"bend {point_id(system, f, p)} {point_id(system, f, p + 1)} {point_id(system, f, p + 2)}")
    return "\n".join(out) + "\n"


def cellmd_forcefield(system: System):
    out = [f"# {system.label}: written by bench/cytosim"] + fibre_drag(system)
    if system.clamps:
        out.append("particle clamp fixed")
    out.append(f"bond seg harmonic k {fmt(system.spring_k)} r0 {fmt(system.segmentation)}")
    if system.links:
        out.append(f"bond link harmonic k {fmt(system.link_stiffness)} r0 0")
    out.append(f"angle bend wlc_bending kappa {fmt(system.rigidity)} l0 {fmt(system.segmentation)}")
    return "\n".join(out) + "\n"


def box(system: System):
    lo, hi = extent(system)
    return "box " + "  ".join(f"{axis} {fmt(a)} {fmt(b)} f" for axis, a, b in zip("xyz", lo, hi))


def cellmd_deck(system: System, variant, dt, tolerance=1e-6):
    """The deck of `system` run by cellmd variant `variant` at time step `dt`."""
    integrator, constrained = VARIANTS[variant]
    every = system.frame_every(dt)
    out = [
        f"# {system.label}, cellmd variant {variant}: written by bench/cytosim",
        "units cell",
        "topology system.top",
        "forcefield system.ff",
        box(system),
        f"integrator {integrator}" + (f" solver {system.implicit_solver}" if integrator == "implicit" and not constrained and system.implicit_solver != "cg" else ""),
        f"temperature {fmt(system.temperature())}   # kT = {system.kT} pN·µm",
        f"timestep {fmt(dt)}",
        f"seed {system.seed}",
    ]
    for n, (fibre, point, force) in enumerate(system.loads):
        out.append(f"group tip{n} id {point_id(system, fibre, point)}")
        out.append(f"external load{n} tip{n} constant_force fx {fmt(force[0])} fy {fmt(force[1])} fz {fmt(force[2])}")
    if constrained:
        out.append(f"constrain seg tolerance {fmt(tolerance)}")
    out += [
        f"thermo {every} step time pe/wlc_bending",
        f"dump frames every {every} xyz frames.xyz",
        f"run {system.steps(dt)}",
    ]
    return "\n".join(out) + "\n"


def write_cellmd(system: System, variant, dt, work):
    os.makedirs(work, exist_ok=True)
    for name, text in (("system.top", cellmd_topology(system)), ("system.ff", cellmd_forcefield(system)), ("system.in", cellmd_deck(system, variant, dt))):
        with open(os.path.join(work, name), "w") as f:
            f.write(text)
    return os.path.join(work, "system.in")


def write_cytosim(system: System, dt, precondition, work):
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "config.cym")
    with open(path, "w") as f:
        f.write(cytosim_config(system, dt, precondition))
    return path
