// The implicit step with constrained bonds (`constrain`) on the device, as
// the CPU's projected conjugate gradients (src/integrate/implicit.rs,
// `projected_cg`; Gould, Hribar & Nocedal, SIAM J. Sci. Comput. 23, 1376
// (2001)): min ½ΔxᵀAΔx − bᵀΔx subject to JΔx = 0, J the constraint
// gradients û_k at the current positions, with the projected Jacobi
// preconditioner. Every projection r ← r − Jᵀμ, μ = S⁻¹JD⁻¹r with
// S = JD⁻¹Jᵀ, solves S by an inner Jacobi-preconditioned CG (the CPU
// factorises S by sparse Cholesky), all inside `implicit_solve_constrained`'s one
// workgroup. D⁻¹ is the Jacobi diagonal's inverse, 0 for a fixed particle.
// At the end the constraint tensions are −μ of the residual AΔx − b. SHAKE
// (shaders/common/shake.wgsl) then removes the second-order drift of the
// lengths, as on the CPU.

// The constraints' header words of `imp_topo` (IMP_CONSTRAINTS …
// IMP_V_CONSTRAINTS), CONSTRAINT_VEC4 and J_END are the prelude's (src/gpu/prelude.rs).
// Scalars of a constraint's second entry.
const C_MU: u32 = 0u;
const C_R: u32 = 1u;
const C_P: u32 = 2u;
const C_Q: u32 = 3u;

fn c_entry(k: u32, e: u32) -> u32 {
    return imp_topo[IMP_V_CONSTRAINTS] + CONSTRAINT_VEC4 * k + e;
}

// D⁻¹ of the projection: the Jacobi diagonal's inverse, 0 for a fixed particle.
fn projection_dinv(i: u32) -> vec3<f32> {
    return select(imp[P.n * VEC_DINV + i].xyz, vec3<f32>(0.0), imp_drag(i) == 0.0);
}

// (Jᵀ·s)_i for the constraint scalar `which`: Σ over i's constraints of ±û_k·s_k.
fn jt_at(i: u32, which: u32) -> vec3<f32> {
    var out = vec3<f32>(0.0);
    let end = imp_topo[imp_topo[IMP_OFF_CSLOT_START] + i + 1u];
    for (var s = imp_topo[imp_topo[IMP_OFF_CSLOT_START] + i]; s < end; s++) {
        let slot = imp_topo[imp_topo[IMP_OFF_CSLOTS] + s];
        let k = slot & ~J_END;
        let u = imp[c_entry(k, 0u)];
        let value = imp[c_entry(k, 1u)][which] * u.w; // w: 1 for an active constraint
        out += select(-u.xyz, u.xyz, (slot & J_END) != 0u) * value;
    }
    return out;
}

// (J·D⁻¹·v)_k with v_i given by `at_i`, `at_j` at the constraint's ends.
fn j_dinv(k: u32, vi: vec3<f32>, vj: vec3<f32>) -> f32 {
    let at = imp_topo[IMP_OFF_CONSTRAINTS] + 2u * k;
    let u = imp[c_entry(k, 0u)];
    return u.w * dot(u.xyz, projection_dinv(imp_topo[at + 1u]) * vj - projection_dinv(imp_topo[at]) * vi);
}

// μ = S⁻¹·J·D⁻¹·r for the particle vector `section` (inner CG, to the
// outer tolerance or 2m + 20 iterations), left in the constraints' C_MU.
fn constraint_multipliers(local: u32, section: u32, tolerance: f32) {
    let m = imp_topo[IMP_CONSTRAINTS];
    var sums = vec3<f32>(0.0);
    for (var k = local; k < m; k += WORKGROUP) {
        let at = imp_topo[IMP_OFF_CONSTRAINTS] + 2u * k;
        let rhs = j_dinv(k, imp_vec(section, imp_topo[at]), imp_vec(section, imp_topo[at + 1u]));
        let z = rhs * imp[c_entry(k, 2u)].y;
        imp[c_entry(k, 1u)] = vec4<f32>(0.0, rhs, z, 0.0);
        imp[c_entry(k, 2u)].x = z;
        sums += vec3<f32>(rhs * z, rhs * rhs, 0.0);
    }
    let start = workgroup_sum(local, sums);
    var rz = start.x;
    let threshold = tolerance * sqrt(start.y);
    var residual = sqrt(start.y);
    var iterations = 0u;
    loop {
        if residual <= threshold || iterations >= 2u * m + 20u {
            break;
        }
        storageBarrier();
        // q = S·p = J·D⁻¹·(Jᵀp).
        var pq = 0.0;
        for (var k = local; k < m; k += WORKGROUP) {
            let at = imp_topo[IMP_OFF_CONSTRAINTS] + 2u * k;
            let q = j_dinv(k, jt_at(imp_topo[at], C_P), jt_at(imp_topo[at + 1u], C_P));
            imp[c_entry(k, 1u)][C_Q] = q;
            pq += imp[c_entry(k, 1u)][C_P] * q;
        }
        let curvature = workgroup_sum(local, vec3<f32>(pq, 0.0, 0.0)).x;
        if !(curvature > 0.0) {
            break;
        }
        let alpha = rz / curvature;
        var next = vec3<f32>(0.0);
        for (var k = local; k < m; k += WORKGROUP) {
            var c = imp[c_entry(k, 1u)];
            c[C_MU] += alpha * c[C_P];
            c[C_R] -= alpha * c[C_Q];
            let z = c[C_R] * imp[c_entry(k, 2u)].y;
            imp[c_entry(k, 1u)] = c;
            imp[c_entry(k, 2u)].x = z;
            next += vec3<f32>(c[C_R] * z, c[C_R] * c[C_R], 0.0);
        }
        let after = workgroup_sum(local, next);
        let beta = after.x / rz;
        rz = after.x;
        residual = sqrt(after.y);
        storageBarrier();
        for (var k = local; k < m; k += WORKGROUP) {
            imp[c_entry(k, 1u)][C_P] = imp[c_entry(k, 2u)].x + beta * imp[c_entry(k, 1u)][C_P];
        }
        iterations += 1u;
    }
    storageBarrier();
}

// r ← r − Jᵀ·S⁻¹·J·D⁻¹·r for the particle vector `section` (a change of λ
// only: r stays consistent with the null space of J).
fn project_residual(local: u32, section: u32, tolerance: f32) {
    constraint_multipliers(local, section, tolerance);
    for (var i = local; i < P.n; i += WORKGROUP) {
        imp[P.n * section + i] = vec4<f32>(imp_vec(section, i) - jt_at(i, C_MU), 0.0);
    }
    storageBarrier();
}

// The constraints' directions û_k at the current positions (w: 1 where a
// constraint has a moving end), and the inverse diagonal of S.
fn constraint_directions(local: u32) {
    let m = imp_topo[IMP_CONSTRAINTS];
    for (var k = local; k < m; k += WORKGROUP) {
        let at = imp_topo[IMP_OFF_CONSTRAINTS] + 2u * k;
        let i = imp_topo[at];
        let j = imp_topo[at + 1u];
        let d = separation(i, j);
        let u = select(d / length(d), vec3<f32>(0.0), dot(d, d) == 0.0);
        let moving = imp_drag(i) != 0.0 || imp_drag(j) != 0.0;
        imp[c_entry(k, 0u)] = vec4<f32>(u, select(0.0, 1.0, moving));
        let diagonal = dot(u * u, projection_dinv(i) + projection_dinv(j));
        imp[c_entry(k, 2u)] = vec4<f32>(0.0, select(0.0, 1.0 / diagonal, moving && diagonal > 0.0), 0.0, 0.0);
    }
    storageBarrier();
}

// The constrained step (the solve kernel of a model with constraints): as
// the CPU, from Δx = 0, converged when |z|/|z₀| ≤ tolerance; then the
// tensions −μ(AΔx − b) into the constraints' third entries (z).
@compute @workgroup_size(256)
fn implicit_solve_constrained(@builtin(local_invocation_index) local: u32) {
    if !begin_solve(local) {
        return;
    }
    let limits = workgroupUniformLoad(&workgroup_limits);
    let tolerance = bitcast<f32>(limits.y);
    let cap = limits.x;
    let n = P.n;
    constraint_directions(local);
    for (var i = local; i < n; i += WORKGROUP) {
        imp[n * VEC_R + i] = vec4<f32>(implicit_rhs(i), 0.0);
        imp[n * VEC_X + i] = vec4<f32>(0.0);
    }
    storageBarrier();
    project_residual(local, VEC_R, tolerance);
    var sums = vec3<f32>(0.0);
    for (var i = local; i < n; i += WORKGROUP) {
        let r = imp_vec(VEC_R, i);
        let z = projection_dinv(i) * r;
        imp[n * VEC_Z + i] = vec4<f32>(z, 0.0);
        imp[n * VEC_P + i] = vec4<f32>(z, 0.0);
        sums += vec3<f32>(dot(r, z), dot(z, z), 0.0);
    }
    let start = workgroup_sum(local, sums);
    var rz = start.x;
    let reference = max(sqrt(start.y), 1.1754944e-38);
    var residual = sqrt(start.y) / reference;
    var iterations = 0u;
    // Products of p until converged, then one of Δx (the residual AΔx − b
    // for the constraint forces) through the same call.
    var section = VEC_P;
    if residual <= tolerance || iterations >= cap {
        section = VEC_X;
    }
    loop {
        let curvature = multiply(local, section);
        if section == VEC_X {
            break;
        }
        if !(curvature > 0.0) {
            section = VEC_X;
            continue;
        }
        let alpha = rz / curvature;
        for (var i = local; i < n; i += WORKGROUP) {
            imp[n * VEC_X + i] = vec4<f32>(imp_vec(VEC_X, i) + alpha * imp_vec(VEC_P, i), 0.0);
            imp[n * VEC_R + i] = vec4<f32>(imp_vec(VEC_R, i) - alpha * imp_vec(VEC_Q, i), 0.0);
        }
        storageBarrier();
        project_residual(local, VEC_R, tolerance);
        var next = vec3<f32>(0.0);
        for (var i = local; i < n; i += WORKGROUP) {
            let r = imp_vec(VEC_R, i);
            let z = projection_dinv(i) * r;
            imp[n * VEC_Z + i] = vec4<f32>(z, 0.0);
            next += vec3<f32>(dot(r, z), dot(z, z), 0.0);
        }
        let after = workgroup_sum(local, next);
        let beta = after.x / rz;
        rz = after.x;
        residual = sqrt(after.y) / reference;
        for (var i = local; i < n; i += WORKGROUP) {
            imp[n * VEC_P + i] = vec4<f32>(imp_vec(VEC_Z, i) + beta * imp_vec(VEC_P, i), 0.0);
        }
        iterations += 1u;
        if residual <= tolerance || iterations >= cap {
            section = VEC_X;
        }
    }
    // The constraint forces: μ of the residual AΔx − b; tension −μ.
    for (var i = local; i < n; i += WORKGROUP) {
        imp[n * VEC_Q + i] = vec4<f32>(imp_vec(VEC_Q, i) - implicit_rhs(i), 0.0);
    }
    storageBarrier();
    constraint_multipliers(local, VEC_Q, tolerance);
    for (var k = local; k < imp_topo[IMP_CONSTRAINTS]; k += WORKGROUP) {
        imp[c_entry(k, 2u)].z = -imp[c_entry(k, 1u)][C_MU];
    }
    clamp_step(local);
    if local == 0u {
        imp[imp_topo[IMP_V_REPORT]] = vec4<f32>(bitcast<f32>(iterations), residual, 0.0, 0.0);
        if residual > tolerance {
            atomicOr(&status[ST_HALTED], HALT_SOLVE);
        }
    }
}
