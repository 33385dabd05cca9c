"""Reference values the benchmark's observables are checked against.

- **Bending energy of thermal fibres, scheme by scheme.** A nearly straight
  fibre of n points with bending E = (κ/2ℓ³)Σ|x_{i−1} − 2x_i + x_{i+1}|²
  (what (κ/ℓ)(1 − t·t') is on inextensible segments) has, in each of its two
  transverse directions, the stiffness K = (κ/ℓ³)DᵀD (D the second
  difference) and equal drag γ per point; its n − 2 bending modes (eigenvalues
  k_j of K) hold kT/2 each at equilibrium, kT per mode over both directions.
  A time-stepping scheme of step dt changes that share by a factor g(λ),
  λ = k_j·dt/γ, and relaxes a mode started at zero (a straight fibre) as
  1 − a(λ)^{2m} after m steps:
  backward Euler (Cytosim's step, cellmd's `integrator implicit`):
  a = 1/(1 + λ), g = 1/(1 + λ/2); Euler–Maruyama (explicit):
  a = 1 − λ, g = 1/(1 − λ/2) (Ottinger 1996, *Stochastic Processes in
  Polymeric Fluids*, ch. 3: the stationary variance of the discretised
  Ornstein–Uhlenbeck process). Summed over modes this is the expected
  bending energy of the run at each frame; 'equipartition' is g = 1, a → 0.
- **Tangent correlation at equilibrium** of the discrete worm-like chain:
  ⟨t_s·t_{s+k}⟩ = (coth β − 1/β)^k, β = κ/(ℓ·kT).
- **Elastica of a clamped–free fibre under a dead end load P** (Timoshenko &
  Gere 1961, *Theory of Elastic Stability*, §2.7): P_c = π²κ/(4L²); past it
  the tip turns by α with √(P/P_c) = (2/π)·K(sin(α/2)), K the complete
  elliptic integral of the first kind. The discrete elastica of the same
  chain (segments ℓ, the first one held, energy Σ(κ/ℓ)(1 − cos Δθ) +
  PℓΣcos θ) is solved by Newton's method: it is what both engines should
  reach, free of the discretisation error.
- **Crosslinked bundle under a small side load**: the linear response of
  the two chains' transverse displacements (bending K per fibre, link
  stiffness between linked points, the clamped points held), solved exactly.
"""

import math


def jacobi_eigenvalues(a, sweeps=60):
    """Eigenvalues of a small symmetric matrix (cyclic Jacobi rotations)."""
    n = len(a)
    a = [row[:] for row in a]
    for _ in range(sweeps):
        off = sum(a[i][j] ** 2 for i in range(n) for j in range(n) if i != j)
        if off < 1e-22 * sum(a[i][i] ** 2 for i in range(n)):
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                if abs(a[p][q]) < 1e-300:
                    continue
                theta = (a[q][q] - a[p][p]) / (2 * a[p][q])
                t = (1 if theta >= 0 else -1) / (abs(theta) + math.sqrt(theta * theta + 1))
                c = 1 / math.sqrt(t * t + 1)
                s = t * c
                for k in range(n):
                    akp, akq = a[k][p], a[k][q]
                    a[k][p], a[k][q] = c * akp - s * akq, s * akp + c * akq
                for k in range(n):
                    apk, aqk = a[p][k], a[q][k]
                    a[p][k], a[q][k] = c * apk - s * aqk, s * apk + c * aqk
    return sorted(a[i][i] for i in range(n))


def bending_matrix(points, kappa, ell):
    """(κ/ℓ³)·DᵀD for one transverse direction of a free chain of `points`."""
    k = [[0.0] * points for _ in range(points)]
    c = kappa / ell**3
    for j in range(points - 2):
        row = {j: 1.0, j + 1: -2.0, j + 2: 1.0}
        for a, va in row.items():
            for b, vb in row.items():
                k[a][b] += c * va * vb
    return k


def bending_modes(points, kappa, ell):
    """The n − 2 non-zero bending eigenvalues k_j (pN/µm) of a free chain."""
    values = jacobi_eigenvalues(bending_matrix(points, kappa, ell))
    return values[2:]


def scheme_factors(lam, scheme):
    """(a, g) of one mode at λ = k·dt/γ: per-step decay and equilibrium share."""
    if scheme == "implicit":
        return 1 / (1 + lam), 1 / (1 + lam / 2)
    if scheme == "explicit":
        if lam >= 2:
            return float("inf"), float("inf")
        return 1 - lam, 1 / (1 - lam / 2)
    raise ValueError(scheme)


def bending_energy(modes, kT, gamma, dt, scheme, t):
    """Expected bending energy of one fibre (pN·µm) at time t from straight."""
    total = 0.0
    for k in modes:
        a, g = scheme_factors(k * dt / gamma, scheme)
        m = round(t / dt)
        total += kT * g * (1 - a ** (2 * m))
    return total


def equipartition(modes, kT):
    return kT * len(modes)


def tangent_correlation(kappa, ell, kT, lag):
    beta = kappa / (ell * kT)
    return (1 / math.tanh(beta) - 1 / beta) ** lag


# -------------------------------------------------------------------- elastica


def elliptic_k(k):
    """Complete elliptic integral of the first kind K(k) (modulus k), by the AGM."""
    a, b = 1.0, math.sqrt(1 - k * k)
    while abs(a - b) > 1e-15 * a:
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2 * a)


def euler_load(kappa, length):
    return math.pi**2 * kappa / (4 * length**2)


def elastica_tip_angle(ratio):
    """Tip angle α (rad) of the continuum clamped–free elastica at P/P_c = ratio."""
    if ratio <= 1:
        return 0.0
    lo, hi = 0.0, 1.0 - 1e-15
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if 2 / math.pi * elliptic_k(mid) < math.sqrt(ratio):
            lo = mid
        else:
            hi = mid
    return 2 * math.asin(0.5 * (lo + hi))


def critical_load_from_angle(load, alpha):
    """P_c implied by a tip angle α at load P: P / ((2/π)K(sin(α/2)))²."""
    return load / (2 / math.pi * elliptic_k(math.sin(alpha / 2))) ** 2


def solve_tridiagonal(lower, diag, upper, rhs):
    n = len(diag)
    c, d = [0.0] * n, [0.0] * n
    c[0], d[0] = upper[0] / diag[0] if n > 1 else 0.0, rhs[0] / diag[0]
    for i in range(1, n):
        m = diag[i] - lower[i] * c[i - 1]
        c[i] = upper[i] / m if i < n - 1 else 0.0
        d[i] = (rhs[i] - lower[i] * d[i - 1]) / m
    x = [0.0] * n
    x[-1] = d[-1]
    for i in range(n - 2, -1, -1):
        x[i] = d[i] - c[i] * x[i + 1]
    return x


def discrete_elastica(segments, ell, kappa, load):
    """Segment angles θ_1 … θ_N of the clamped chain's buckled equilibrium
    (θ_1 = 0 held), or all zeros below its buckling load."""
    n = segments
    ratio = load / euler_load(kappa, n * ell)
    alpha = max(elastica_tip_angle(ratio), 0.3)
    theta = [alpha * math.sin(0.5 * math.pi * i / (n - 1)) for i in range(n)]
    c = kappa / ell
    for _ in range(100):
        grad, lower, diag, upper = [], [], [], []
        for i in range(1, n):
            g = -load * ell * math.sin(theta[i])
            h = -load * ell * math.cos(theta[i])
            lo = up = 0.0
            if i >= 1:
                g += c * math.sin(theta[i] - theta[i - 1])
                h += c * math.cos(theta[i] - theta[i - 1])
                lo = -c * math.cos(theta[i] - theta[i - 1]) if i > 1 else 0.0
            if i < n - 1:
                g -= c * math.sin(theta[i + 1] - theta[i])
                h += c * math.cos(theta[i + 1] - theta[i])
                up = -c * math.cos(theta[i + 1] - theta[i])
            grad.append(g)
            lower.append(lo)
            diag.append(h)
            upper.append(up)
        step = solve_tridiagonal(lower, diag, upper, [-g for g in grad])
        for i in range(1, n):
            theta[i] += step[i - 1]
        if max(abs(s) for s in step) < 1e-13:
            break
    if abs(theta[-1]) < 1e-6:
        return [0.0] * n
    return [abs(t) for t in theta] if theta[-1] > 0 else [-t for t in theta]


def elastica_points(theta, ell):
    """(x, y) of the chain's points from its segment angles, the first at 0."""
    pts = [(0.0, 0.0)]
    for t in theta:
        x, y = pts[-1]
        pts.append((x + ell * math.cos(t), y + ell * math.sin(t)))
    return pts


# ---------------------------------------------------------------------- bundle


def solve_dense(a, b):
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(m[r][col]))
        m[col], m[pivot] = m[pivot], m[col]
        for r in range(col + 1, n):
            f = m[r][col] / m[col][col]
            if f:
                for k in range(col, n + 1):
                    m[r][k] -= f * m[col][k]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        x[r] = (m[r][n] - sum(m[r][k] * x[k] for k in range(r + 1, n))) / m[r][r]
    return x


def bundle_linear_response(system):
    """Transverse displacement of every point (fibre-major) under the loads'
    components along y, to first order in the load."""
    n, nf = system.points, len(system.fibres)
    size = n * nf
    k = [[0.0] * size for _ in range(size)]
    block = bending_matrix(n, system.rigidity, system.segmentation)
    for f in range(nf):
        for i in range(n):
            for j in range(n):
                k[f * n + i][f * n + j] += block[i][j]
    for a, i, b, j in system.links:
        p, q = a * n + i, b * n + j
        k[p][p] += system.link_stiffness
        k[q][q] += system.link_stiffness
        k[p][q] -= system.link_stiffness
        k[q][p] -= system.link_stiffness
    force = [0.0] * size
    for f, p, (fx, fy, fz) in system.loads:
        force[f * n + p] += fy
    held = {f * n + p for f, p in system.clamps}
    free = [i for i in range(size) if i not in held]
    y = solve_dense([[k[i][j] for j in free] for i in free], [force[i] for i in free])
    out = [0.0] * size
    for i, v in zip(free, y):
        out[i] = v
    return out
