"""The pass/fail checks of each system, run by run and engine against engine.

Every check is `agree` of `analysis` (|a − b| ≤ 3σ + budget); the budgets
are bounds on known systematic differences, computed here from the model:

- (a) bending energy against its scheme's prediction: budget (2/β)·E,
  β = κ/(ℓkT), the relative size ⟨θ²⟩ of the joint angles, the order of
  the terms the linear (weakly bent) theory leaves out.
- (b) tip angle against the discrete elastica: Cytosim holds the clamp with
  two pickets of stiffness k_c ℓ apart; the clamp moment M = P·y_tip turns
  it by ≈ 2M/(k_c ℓ²), a budget for Cytosim's runs only (cellmd fixes the
  points). Cytosim's load is a picket D away: its force drops by up to
  L/D as the tip travels; the tip angle's change for that is added.
- (c) tip deflection against the linear response: 1 % for the geometric
  nonlinearity at deflections of ~6 % of L (the first correction is of
  order (δ/L)² ≈ 0.4 %), plus for Cytosim the tip shift of its clamp's
  rotation under the root moment F·L.
"""

import math

from . import analysis, theory


def free_checks(system, runs):
    """`runs`: [(label, scheme, dt, observables)], Cytosim's first per dt."""
    out = []
    beta = system.rigidity / (system.segmentation * system.kT)
    for label, scheme, dt, obs in runs:
        pred = analysis.free_prediction(system, scheme, dt, obs["late_times"])
        ok, z = analysis.agree(obs["energy"], (pred["energy"], 0.0), budget=2 / beta * pred["energy"])
        out.append((label, f"bending energy {obs['energy'][0]:.4g} ± {obs['energy'][1]:.2g} vs {scheme} dt={dt:g} prediction {pred['energy']:.4g} (equipartition {pred['equipartition']:.4g}) pN·µm", ok, z))
    reference = {dt: (label, obs) for label, scheme, dt, obs in runs if label.startswith("Cytosim")}
    if not reference:
        return out
    smallest = min(reference)
    for label, scheme, dt, obs in runs:
        if label.startswith("Cytosim"):
            continue
        same = dt in reference and scheme == "implicit"
        ref_label, ref = reference[dt] if same else reference[smallest]
        pairs = [("R² at the end (µm²)", obs["r2_end"], ref["r2_end"]), ("R² over the second half (µm²)", obs["r2_late"], ref["r2_late"])]
        if same:
            pairs.append(("bending energy (pN·µm)", obs["energy"], ref["energy"]))
            pairs += [(f"tangent correlation, lag {lag}", obs["tcorr"][lag], ref["tcorr"][lag]) for lag in analysis.TCORR_LAGS]
        for name, a, b in pairs:
            ok, z = analysis.agree(a, b)
            out.append((f"{label} vs {ref_label}", f"{name}: {a[0]:.5g} ± {a[1]:.2g} vs {b[0]:.5g} ± {b[1]:.2g}", ok, z))
    return out


def cytosim_clamp_turn(system, moment):
    return 2 * moment / (system.clamp_stiffness * system.segmentation**2)


def buckling_budget(system, load, alpha, cytosim):
    if not cytosim:
        return 0.0
    theta = theory.discrete_elastica(system.segments, system.segmentation, system.rigidity, load)
    y_tip = theory.elastica_points(theta, system.segmentation)[-1][1]
    softer = theory.discrete_elastica(system.segments, system.segmentation, system.rigidity, load * (1 - system.length / system.load_distance))
    return cytosim_clamp_turn(system, load * y_tip) + abs(theta[-1] - softer[-1])


def buckling_checks(system, runs):
    out = []
    euler = theory.euler_load(system.rigidity, system.length)
    for label, scheme, dt, obs in runs:
        estimates, reference = [], []
        for item in obs:
            (alpha, se), ref = item["angle"], item["elastica_angle"]
            ratio = item["load"] / euler
            if ref == 0.0:
                ok = alpha < 0.2
                out.append((label, f"P = {ratio:.2f} P_c: not buckled, tip angle {alpha:.3f} rad < 0.2", ok, float("nan")))
                continue
            budget = buckling_budget(system, item["load"], alpha, label.startswith("Cytosim"))
            ok, z = analysis.agree((alpha, se), (ref, 0.0), budget)
            out.append((label, f"P = {ratio:.2f} P_c: tip angle {alpha:.4f} ± {se:.2g} vs discrete elastica {ref:.4f} rad (budget {budget:.2g}); shape RMS {item['shape_error']:.2%} of L", ok, z))
            estimates.append(theory.critical_load_from_angle(item["load"], alpha))
            reference.append(theory.critical_load_from_angle(item["load"], ref))
        if estimates:
            m, r = sum(estimates) / len(estimates), sum(reference) / len(reference)
            out.append((label, f"critical force from the post-buckled angles {m:.4g} pN (discrete chain {r:.4g}, continuum π²κ/4L² = {euler:.4g}); spread {min(estimates):.4g}–{max(estimates):.4g}", abs(m / r - 1) < 0.02, float("nan")))
    return out


def loaded_fibre_alone(system):
    """Linear tip deflection of the clamped fibre if it carried the whole load
    without its partner: the bound the crosslinked bundle must beat."""
    clamped = system.clamps[0][0]
    alone = type(system)(**{**system.__dict__, "fibres": [system.fibres[clamped]], "links": [], "clamps": [(0, p) for f, p in system.clamps if f == clamped], "loads": [(0, p, force) for _, p, force in system.loads]})
    return theory.bundle_linear_response(alone)[-1]


def bundle_checks(system, runs):
    out = []
    force = sum(abs(f[1]) for _, _, f in system.loads)
    alone = loaded_fibre_alone(system)
    for label, scheme, dt, obs in runs:
        for item in obs:
            budget = 0.01 * abs(item["linear"])
            if label.startswith("Cytosim"):
                budget += cytosim_clamp_turn(system, force * system.length) * system.length
            ok, z = analysis.agree(item["tip"], (item["linear"], 0.0), budget)
            out.append((label, f"fibre {item['fibre']} tip deflection {item['tip'][0]:.5g} ± {item['tip'][1]:.2g} vs linear response {item['linear']:.5g} µm (budget {budget:.2g}; the clamped fibre alone under the load: {alone:.4g})", ok, z))
    return out


def engine_pairs(runs, key):
    """Each cellmd run against the first Cytosim run at the same dt (or Cytosim's smallest dt)."""
    cyto = {dt: (label, obs) for label, scheme, dt, obs in reversed(runs) if label.startswith("Cytosim")}
    if not cyto:
        return []
    pairs = []
    for label, scheme, dt, obs in runs:
        if label.startswith("Cytosim"):
            continue
        ref_label, ref = cyto.get(dt, cyto[min(cyto)])
        pairs.append((label, ref_label, key(obs), key(ref)))
    return pairs


def cross_checks(system, runs):
    """Engine against engine for (b) and (c): the same observable within 3σ."""
    out = []
    if system.name == "buckling":
        for a, b, xa, xb in engine_pairs(runs, lambda obs: [item["angle"] for item in obs]):
            for item, va, vb in zip(system.loads, xa, xb):
                ok, z = analysis.agree(va, vb, buckling_budget(system, math.sqrt(sum(f * f for f in item[2])), 0, True))
                out.append((f"{a} vs {b}", f"tip angle {va[0]:.4f} ± {va[1]:.2g} vs {vb[0]:.4f} ± {vb[1]:.2g} rad", ok, z))
    if system.name == "bundle":
        for a, b, xa, xb in engine_pairs(runs, lambda obs: [item["tip"] for item in obs]):
            for va, vb in zip(xa, xb):
                ok, z = analysis.agree(va, vb, cytosim_clamp_turn(system, sum(abs(f[1]) for _, _, f in system.loads) * system.length) * system.length)
                out.append((f"{a} vs {b}", f"tip deflection {va[0]:.5g} ± {va[1]:.2g} vs {vb[0]:.5g} ± {vb[1]:.2g} µm", ok, z))
    return out


CHECKS = {"free": free_checks, "buckling": buckling_checks, "bundle": bundle_checks}
