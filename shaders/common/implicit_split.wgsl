// The implicit step's conjugate gradients over every workgroup (the split
// solve; src/gpu/implicit.rs says when it runs): the one-workgroup solve of
// implicit.wgsl, `implicit_solve`, cut into one dispatch per phase, so that
// each product K̃·v and each vector update runs on the whole device. The
// same CG (the Jacobi step as first guess, Jacobi preconditioner, the same
// per-particle rows `apply_row`); its dot products are summed per workgroup
// by a fixed tree into one partial each, and the partials by one workgroup
// in a fixed order, so the same run gives the same bits (no float atomics).
//
// A step encodes, after `implicit_blocks`:
//   `implicit_split_start`          b, x₀ = D⁻¹b, the bodies' weights
//   [`implicit_split_body_dots`]    with body terms: ∇V·v, ∇A·v, g_k·v
//   `implicit_split_product`        q = A·v (v = x₀ first, then p), Σ v·q
//   `implicit_split_residual`       r = b − q, z = p = D⁻¹r, Σ (r·z, r·r, b·b)
//   `implicit_split_first`          (ONE workgroup) the sums, the threshold
// then the host's iteration budget of
//   [`implicit_split_body_dots`], `implicit_split_product`,
//   `implicit_split_alpha`          (ONE workgroup) α = r·z / p·Ap
//   `implicit_split_update`         x += αp, r −= αq, z = D⁻¹r, Σ (r·z, r·r)
//   `implicit_split_direction`      β, p = z + βp, the convergence test
// and `implicit_split_finish` (ONE workgroup: the report; halts with
// HALT_SOLVE as `implicit_solve` does, or with HALT_BUDGET when the budget
// ran out first: the host then takes the step again with a larger one),
// [`implicit_split_clamp`] (with contact: the step clamp's minimum by an
// integer atomicMin on the bits, order-free) and `implicit_move`.
// Once converged, every later kernel of the budget returns at once.

// The entries of the split solve from imp_topo[IMP_V_SPLIT] on (SPLIT_SCALARS,
// SPLIT_STATE, SPLIT_COPY, then SPLIT_PARTIALS …) and HALT_BUDGET are the
// prelude's (src/gpu/prelude.rs).

var<workgroup> split_flag: u32;

fn split_entry(k: u32) -> u32 {
    return imp_topo[IMP_V_SPLIT] + k;
}

// Workgroups of a particle kernel: partial sums are kept for these.
fn split_groups() -> u32 {
    return (P.n + WORKGROUP - 1u) / WORKGROUP;
}

// True (the same in every invocation) when the kernel has nothing to do:
// the run has halted, or `done` (the word of `entry` at w) is set.
fn split_idle(local: u32, entry: u32, done_in_z: bool) -> bool {
    if local == 0u {
        let e = imp[split_entry(entry)];
        split_flag = atomicLoad(&status[ST_HALTED]) | bitcast<u32>(select(e.y, e.z, done_in_z));
    }
    return workgroupUniformLoad(&split_flag) != 0u;
}

// The sum of each invocation's `v` over the workgroup (fixed tree) into the
// workgroup's partial entry.
fn split_partial(wg: vec3<u32>, local: u32, v: vec3<f32>) {
    let total = workgroup_sum(local, v);
    let group = wg.y * P.groups_x + wg.x;
    if local == 0u && group < split_groups() {
        imp[split_entry(SPLIT_PARTIALS) + group] = vec4<f32>(total, 0.0);
    }
}

// The partials summed in a fixed order (each invocation its stride, then
// the tree): the same bits in every workgroup that asks.
fn split_total(local: u32) -> vec3<f32> {
    var v = vec3<f32>(0.0);
    let groups = split_groups();
    for (var g = local; g < groups; g += WORKGROUP) {
        v += imp[split_entry(SPLIT_PARTIALS) + g].xyz;
    }
    return workgroup_sum(local, v);
}

@compute @workgroup_size(256)
fn implicit_split_start(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if halted() {
        return;
    }
    if i < P.n {
        let b = implicit_rhs(i);
        imp[P.n * VEC_R + i] = vec4<f32>(b, 0.0);
        imp[P.n * VEC_X + i] = vec4<f32>(imp[P.n * VEC_DINV + i].xyz * b, 0.0);
    }
    if BODY_TERMS && i < P.n_bodies {
        store_body_weight(i);
    }
    if i == 0u {
        imp[split_entry(SPLIT_STATE)] = vec4<f32>(0.0, 0.0, 0.0, bitcast<f32>(VEC_X));
    }
}

@compute @workgroup_size(256)
fn implicit_split_body_dots(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if split_idle(local, SPLIT_STATE, false) {
        return;
    }
    let k = linear_index(wg, local);
    let section = bitcast<u32>(imp[split_entry(SPLIT_STATE)].w);
    if k < P.n_body_nodes {
        node_dot(k, section);
    }
    if k < P.n_bodies {
        body_dot(k, section);
    }
}

@compute @workgroup_size(256)
fn implicit_split_product(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if split_idle(local, SPLIT_STATE, false) {
        return;
    }
    let i = linear_index(wg, local);
    let section = bitcast<u32>(imp[split_entry(SPLIT_STATE)].w);
    var vq = 0.0;
    if i < P.n {
        let q = apply_row(i, section);
        imp[P.n * VEC_Q + i] = vec4<f32>(q, 0.0);
        vq = dot(imp_vec(section, i), q);
    }
    split_partial(wg, local, vec3<f32>(vq, 0.0, 0.0));
}

@compute @workgroup_size(256)
fn implicit_split_residual(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if split_idle(local, SPLIT_STATE, false) {
        return;
    }
    let i = linear_index(wg, local);
    var sums = vec3<f32>(0.0);
    if i < P.n {
        sums = first_residual(i);
    }
    split_partial(wg, local, sums);
}

@compute @workgroup_size(256)
fn implicit_split_first(@builtin(local_invocation_index) local: u32) {
    if split_idle(local, SPLIT_STATE, false) {
        return;
    }
    let start = split_total(local);
    if local == 0u {
        let b_norm = sqrt(start.z);
        let residual = sqrt(start.y);
        let threshold = bitcast<f32>(imp_topo[IMP_TOLERANCE]) * b_norm;
        let done = b_norm == 0.0 || residual < threshold;
        imp[split_entry(SPLIT_SCALARS)] = vec4<f32>(start.x, 0.0, threshold, b_norm);
        imp[split_entry(SPLIT_STATE)] = vec4<f32>(0.0, bitcast<f32>(u32(done)), residual, bitcast<f32>(VEC_P));
    }
}

@compute @workgroup_size(256)
fn implicit_split_alpha(@builtin(local_invocation_index) local: u32) {
    if local == 0u {
        split_flag = atomicLoad(&status[ST_HALTED]);
    }
    if workgroupUniformLoad(&split_flag) != 0u {
        return;
    }
    // Read before any invocation writes it (the barriers of `split_total`).
    let state = imp[split_entry(SPLIT_STATE)];
    let curvature = split_total(local).x;
    if local != 0u {
        return;
    }
    let rz = imp[split_entry(SPLIT_SCALARS)].x;
    // The copy is written whatever happens, so `implicit_split_direction` never reads a stale one.
    var done = bitcast<u32>(state.y);
    if done == 0u && !(curvature > 0.0) {
        // Not positive: CG stops here, judged by its residual (as `implicit_solve`).
        done = 1u;
        imp[split_entry(SPLIT_STATE)] = vec4<f32>(state.x, bitcast<f32>(done), state.z, state.w);
    }
    imp[split_entry(SPLIT_COPY)] = vec4<f32>(rz, state.x, bitcast<f32>(done), 0.0);
    if done == 0u {
        imp[split_entry(SPLIT_SCALARS)].y = rz / curvature;
    }
}

@compute @workgroup_size(256)
fn implicit_split_update(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if split_idle(local, SPLIT_STATE, false) {
        return;
    }
    let i = linear_index(wg, local);
    let alpha = imp[split_entry(SPLIT_SCALARS)].y;
    var sums = vec3<f32>(0.0);
    if i < P.n {
        sums = cg_update(i, alpha);
    }
    split_partial(wg, local, sums);
}

// Every workgroup sums the update's partials itself (the same bits in each)
// for β; workgroup 0 records r·z, |r|, the iteration and the convergence
// test. It reads only the alpha kernel's copy, which nothing writes here.
@compute @workgroup_size(256)
fn implicit_split_direction(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if split_idle(local, SPLIT_COPY, true) {
        return;
    }
    let copy = imp[split_entry(SPLIT_COPY)];
    let after = split_total(local);
    let beta = after.x / copy.x;
    let i = linear_index(wg, local);
    if i < P.n {
        cg_direction(i, beta);
    }
    if i == 0u {
        let iterations = bitcast<u32>(copy.y) + 1u;
        let residual = sqrt(after.y);
        let done = residual < imp[split_entry(SPLIT_SCALARS)].z || iterations >= imp_topo[IMP_MAX_ITER];
        imp[split_entry(SPLIT_SCALARS)].x = after.x;
        imp[split_entry(SPLIT_STATE)] = vec4<f32>(bitcast<f32>(iterations), bitcast<f32>(u32(done)), residual, bitcast<f32>(VEC_P));
    }
}

@compute @workgroup_size(1)
fn implicit_split_finish() {
    if halted() {
        return;
    }
    let scalars = imp[split_entry(SPLIT_SCALARS)];
    let state = imp[split_entry(SPLIT_STATE)];
    let iterations = bitcast<u32>(state.x);
    let b_norm = scalars.w;
    let converged = b_norm == 0.0 || state.z < scalars.z;
    let relative = select(state.z / b_norm, 0.0, b_norm == 0.0);
    // z: the most iterations a solve took since the host last cleared it (the budget's measure).
    let most = max(bitcast<u32>(imp[imp_topo[IMP_V_REPORT]].z), iterations);
    imp[imp_topo[IMP_V_REPORT]] = vec4<f32>(bitcast<f32>(iterations), relative, bitcast<f32>(most), 0.0);
    if !converged {
        atomicOr(&status[ST_HALTED], select(HALT_BUDGET, HALT_SOLVE, bitcast<u32>(state.y) != 0u));
    }
    if CONTACT_TERMS {
        // The clamp starts at 1 (the force pass left the explicit step's there).
        atomicStore(&status[ST_FRACTION], 0x3f800000u);
    }
}

@compute @workgroup_size(256)
fn implicit_split_clamp(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if !CONTACT_TERMS || i >= P.n || halted() {
        return;
    }
    let s = contact_move_fraction(i, imp_vec(VEC_X, i));
    if s < 1.0 {
        atomicMin(&status[ST_FRACTION], bitcast<u32>(s));
    }
}
