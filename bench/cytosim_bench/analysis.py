"""Observables of each system from an engine's frames, with standard errors.

Statistical errors: for thermal fibres (a) the fibres are independent, so
a quantity's standard error is the spread of its per-fibre values over √F
(F fibres), whatever the time correlation within a fibre. For (b) and (c)
(one fibre per load, one bundle) it is the batch-means error of the time
series over the settled frames: 4 consecutive batches, SE = sd(batch
means)/√4.

The agreement test (`agree`): two estimates a ± σ_a and b ± σ_b agree when
|a − b| ≤ 3·√(σ_a² + σ_b²) + budget, where `budget` is a stated bound on a
known systematic difference (0 unless the system says otherwise): for
independent Gaussian errors a true agreement fails it with probability
0.27 %.
"""

import math

from . import theory


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def unit(a):
    n = math.sqrt(dot(a, a))
    return (a[0] / n, a[1] / n, a[2] / n)


def tangents(points):
    return [unit(sub(points[i + 1], points[i])) for i in range(len(points) - 1)]


def mean_se(values):
    n = len(values)
    m = sum(values) / n
    if n < 2:
        return m, float("nan")
    var = sum((v - m) ** 2 for v in values) / (n - 1)
    return m, math.sqrt(var / n)


def batch_mean_se(series, batches=4):
    size = len(series) // batches
    if size < 1:
        return mean_se(series)
    means = [sum(series[k * size : (k + 1) * size]) / size for k in range(batches)]
    return sum(series) / len(series), mean_se(means)[1]


def agree(a, b, budget=0.0):
    """(passes, |a − b| in units of the combined standard error)."""
    sigma = math.hypot(a[1], b[1])
    diff = abs(a[0] - b[0])
    z = diff / sigma if sigma > 0 else float("inf")
    return diff <= 3 * sigma + budget, z


# ----------------------------------------------------------- (a) free fibres

TCORR_LAGS = (1, 10, 25)


def free_observables(system, frames):
    """R²(t) per frame, and over the second half of the run the bending
    energy (all fibres) and the tangent correlations, each (mean, SE)."""
    c = system.rigidity / system.segmentation
    r2, energy_by_frame = [], []
    per_fibre_energy = [[] for _ in frames[0][1]]
    per_fibre_r2 = [[] for _ in frames[0][1]]
    per_fibre_tcorr = {lag: [[] for _ in frames[0][1]] for lag in TCORR_LAGS}
    for t, fibres in frames:
        values = [dot(sub(f[-1], f[0]), sub(f[-1], f[0])) for f in fibres]
        r2.append((t, mean_se(values)))
        energies = []
        for k, f in enumerate(fibres):
            ts = tangents(f)
            e = c * sum(1 - dot(ts[i], ts[i + 1]) for i in range(len(ts) - 1))
            energies.append(e)
            if t >= 0.5 * system.time - 1e-9:
                per_fibre_energy[k].append(e)
                per_fibre_r2[k].append(values[k])
                for lag in TCORR_LAGS:
                    per_fibre_tcorr[lag][k].append(sum(dot(ts[i], ts[i + lag]) for i in range(len(ts) - lag)) / (len(ts) - lag))
        energy_by_frame.append((t, sum(energies)))
    nf = len(frames[0][1])
    energy = mean_se([sum(e) / len(e) for e in per_fibre_energy])
    return {
        "r2": r2,
        "r2_end": r2[-1][1],
        "r2_late": mean_se([sum(v) / len(v) for v in per_fibre_r2]),
        "energy": (energy[0] * nf, energy[1] * nf),
        "energy_frames": energy_by_frame,
        "tcorr": {lag: mean_se([sum(v) / len(v) for v in per_fibre_tcorr[lag]]) for lag in TCORR_LAGS},
        "late_times": [t for t, _ in frames if t >= 0.5 * system.time - 1e-9],
    }


def free_prediction(system, scheme, dt, late_times):
    """Expected bending energy of all fibres over the late frames (see theory)."""
    modes = theory.bending_modes(system.points, system.rigidity, system.segmentation)
    gamma = system.point_drag()
    nf = len(system.fibres)
    expected = sum(theory.bending_energy(modes, system.kT, gamma, dt, scheme, t) for t in late_times) / len(late_times)
    return {"energy": nf * expected, "equipartition": nf * theory.equipartition(modes, system.kT)}


# -------------------------------------------------------------- (b) buckling


def tip_angle(points):
    """Angle (rad) between the last segment and the first (the clamped one)."""
    ts = tangents(points)
    return math.acos(max(-1.0, min(1.0, dot(ts[0], ts[-1]))))


def planar_shape(points):
    """(x, y) of the points in the plane of the first segment and the tip,
    y ≥ 0: the buckled fibre seen flat, whatever plane it chose."""
    origin = points[0]
    ex = unit(sub(points[1], points[0]))
    r = sub(points[-1], origin)
    perp = sub(r, tuple(dot(r, ex) * e for e in ex))
    if dot(perp, perp) < 1e-24:
        return [(dot(sub(p, origin), ex), 0.0) for p in points]
    ey = unit(perp)
    return [(dot(sub(p, origin), ex), dot(sub(p, origin), ey)) for p in points]


def settled(system, frames, fraction=0.4):
    return [fr for fr in frames if fr[0] >= (1 - fraction) * system.time - 1e-9]


def buckling_observables(system, frames):
    """Per fibre: tip angle (mean, SE) over the settled frames and the RMS
    distance of its points from the discrete elastica at its load, / L."""
    late = settled(system, frames)
    out = []
    for k, (_, _, force) in enumerate(system.loads):
        load = math.sqrt(dot(force, force))
        theta = theory.discrete_elastica(system.segments, system.segmentation, system.rigidity, load)
        reference = theory.elastica_points(theta, system.segmentation)
        angles = [tip_angle(fs[k]) for _, fs in late]
        shape_err = []
        for _, fs in late:
            shape = planar_shape(fs[k])
            shape_err.append(math.sqrt(sum((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 for a, b in zip(shape, reference)) / len(shape)) / system.length)
        out.append({"load": load, "angle": batch_mean_se(angles), "elastica_angle": theta[-1], "shape_error": sum(shape_err) / len(shape_err)})
    return out


# ---------------------------------------------------------------- (c) bundle


def bundle_observables(system, frames):
    """Tip displacement along the load (y) of each fibre, (mean, SE) over the
    settled frames, and the linear response it should approach."""
    late = settled(system, frames, fraction=0.75)
    linear = theory.bundle_linear_response(system)
    n = system.points
    out = []
    for f in range(len(system.fibres)):
        y0 = system.point(f, n - 1)[1]
        series = [fs[f][-1][1] - y0 for _, fs in late]
        out.append({"fibre": f + 1, "tip": batch_mean_se(series), "linear": linear[f * n + n - 1]})
    return out
