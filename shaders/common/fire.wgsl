// FIRE minimisation on the device (`minimize`), as src/integrate/fire.rs
// (the equations and their reference are there; the layout in
// src/gpu/fire.rs). Each iteration, after the neighbour check and the force
// pass:
//   1. `fire_partials` (one invocation per particle): per workgroup, the
//      sums P = Σ F·v, Σ|v|², Σ|F|² and the largest |F| over the particles
//      that move (a fixed tree), into that workgroup's partial entry.
//   2. `fire_control` (ONE workgroup): the partials summed in a fixed order;
//      converged when max |F| < ftol (the run halts before moving); else the
//      mixing v ← (1 − α)v + α|v|F̂ (P > 0) or v ← 0 (P ≤ 0), and Δt, α and
//      the count of positive steps updated as on the CPU.
//   3. `fire_move` (one per particle): the mixing, v ← v + Δt·F/m with
//      m = γ·Δt₀, x ← x + Δt·v with the move capped at dmax, in fixed point.
//      With contact between bodies it only takes the step clamp: each contact
//      particle's s_i = L_i/|Δx_i| where it would move farther than
//      L_i = 0.4 × its closest contact distance (the contact pass's), the
//      minimum over particles by an integer atomicMin on the bits (order-free),
//      and then
//   4. `fire_clamped_move` (one per particle): x ← x + s·Δx, the CPU's line
//      search along the move (src/integrate/fire.rs); the velocities are kept.
// A `fixed` particle (mobility 0) and the held axes of a protocol's
// particles have no force here, as the CPU masks them. No float atomics:
// the same minimisation gives the same bits.

@group(1) @binding(5) var<storage, read_write> fire_v: array<vec4<f32>>;
@group(1) @binding(6) var<storage, read_write> fire: array<vec4<f32>>;

// Entries of `fire` (FIRE_STATE, FIRE_MIXING, FIRE_LIMITS, FIRE_CLAMPED, then
// FIRE_PARTIALS …) and FIRE's parameters (FIRE_N_MIN, FIRE_F_INC, …, the
// CPU's) are the prelude's (src/gpu/prelude.rs); src/gpu/fire.rs writes the first three.

var<workgroup> fire_tree: array<vec4<f32>, 256>;
var<workgroup> fire_flag: u32;

// Particle i's force as FIRE sees it: none for a fixed particle, none along
// its held axes.
fn fire_force(i: u32) -> vec3<f32> {
    if fparams[P.off_mobility + topo[i]] == 0.0 {
        return vec3<f32>(0.0);
    }
    return free_axes(i) * force[i].xyz;
}

// Sums x, y, z and takes the largest w over the workgroup (fixed tree); the
// result in invocation 0.
fn fire_reduce(local: u32, v: vec4<f32>) -> vec4<f32> {
    fire_tree[local] = v;
    workgroupBarrier();
    for (var width = WORKGROUP / 2u; width > 0u; width = width >> 1u) {
        if local < width {
            let a = fire_tree[local];
            let b = fire_tree[local + width];
            fire_tree[local] = vec4<f32>(a.xyz + b.xyz, max(a.w, b.w));
        }
        workgroupBarrier();
    }
    return fire_tree[0];
}

@compute @workgroup_size(256)
fn fire_partials(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    var v = vec4<f32>(0.0);
    if i < P.n {
        let f = fire_force(i);
        let vel = fire_v[i].xyz;
        v = vec4<f32>(dot(f, vel), dot(vel, vel), dot(f, f), length(f));
    }
    let total = fire_reduce(local, v);
    if local == 0u {
        fire[FIRE_PARTIALS + wg.y * P.groups_x + wg.x] = total;
    }
}

@compute @workgroup_size(256)
fn fire_control(@builtin(local_invocation_index) local: u32) {
    if local == 0u {
        fire_flag = atomicLoad(&status[ST_HALTED]);
    }
    if workgroupUniformLoad(&fire_flag) != 0u {
        return;
    }
    let blocks = bitcast<u32>(fire[FIRE_LIMITS].w);
    var v = vec4<f32>(0.0);
    for (var b = local; b < blocks; b += WORKGROUP) {
        let p = fire[FIRE_PARTIALS + b];
        v = vec4<f32>(v.xyz + p.xyz, max(v.w, p.w));
    }
    let total = fire_reduce(local, v);
    if local != 0u {
        return;
    }
    var limits = fire[FIRE_LIMITS];
    limits.z = total.w;
    fire[FIRE_LIMITS] = limits;
    if total.w < limits.x {
        atomicOr(&status[ST_HALTED], HALT_CONVERGED);
        return;
    }
    if CONTACT_TERMS {
        // The move's clamp starts at 1 (the force pass left the overdamped step's there).
        atomicStore(&status[ST_FRACTION], 0x3f800000u);
    }
    var state = fire[FIRE_STATE];
    var mixing = fire[FIRE_MIXING];
    var dt = state.x;
    var alpha = state.y;
    var positive = bitcast<u32>(state.z);
    if total.x > 0.0 {
        mixing.x = 1.0 - alpha;
        mixing.y = select(alpha * sqrt(total.y) / sqrt(total.z), 0.0, total.z == 0.0);
        if positive > FIRE_N_MIN {
            dt = min(dt * FIRE_F_INC, mixing.w);
            alpha *= FIRE_F_ALPHA;
        }
        positive += 1u;
    } else {
        mixing.x = 0.0;
        mixing.y = 0.0;
        dt *= FIRE_F_DEC;
        alpha = FIRE_ALPHA0;
        positive = 0u;
    }
    fire[FIRE_STATE] = vec4<f32>(dt, alpha, bitcast<f32>(positive), bitcast<f32>(bitcast<u32>(state.w) + 1u));
    fire[FIRE_MIXING] = mixing;
}

// The move Δt·v, capped at dmax.
fn fire_displacement(v: vec3<f32>) -> vec3<f32> {
    var dx = fire[FIRE_STATE].x * v;
    let moved = length(dx);
    let dmax = fire[FIRE_LIMITS].y;
    if moved > dmax {
        dx *= dmax / moved;
    }
    return dx;
}

// Moves particle i by dx, in fixed point.
fn fire_place(i: u32, dx: vec3<f32>) {
    let placed = wrap_into_box(fixed_add(fixed_of(i), fixed_of_length(dx)), image_of(i));
    state[i] = vec4<u32>(bitcast<vec3<u32>>(placed.x.h), 0u);
    state[P.n + i] = vec4<u32>(placed.x.f, 0u);
    state[2u * P.n + i] = vec4<u32>(bitcast<vec3<u32>>(placed.img), 0u);
}

@compute @workgroup_size(256)
fn fire_move(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    let f = fire_force(i);
    let mixing = fire[FIRE_MIXING];
    let dt = fire[FIRE_STATE].x;
    let dt0 = mixing.z;
    // F/m = F·(Δt₀/γ)/Δt₀², the mobility Δt₀/γ per type.
    let v = mixing.x * fire_v[i].xyz + mixing.y * f + dt * f * (fparams[P.off_mobility + topo[i]] / dt0) / dt0;
    let dx = fire_displacement(v);
    if !(dot(dx, dx) < 1e36) || !(dot(v, v) < 1e36) {
        atomicMin(&status[ST_BLOWUP_PARTICLE], i);
        atomicOr(&status[ST_HALTED], HALT_BLOWUP);
        return;
    }
    fire_v[i] = vec4<f32>(v, 0.0);
    if !CONTACT_TERMS {
        fire_place(i, dx);
        return;
    }
    let s = contact_move_fraction(i, dx);
    if s < 1.0 {
        atomicMin(&status[ST_FRACTION], bitcast<u32>(s));
    }
}

@compute @workgroup_size(256)
fn fire_clamped_move(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    let s = bitcast<f32>(atomicLoad(&status[ST_FRACTION]));
    fire_place(i, s * fire_displacement(fire_v[i].xyz));
    if i == 0u && s < 1.0 {
        fire[FIRE_CLAMPED].x = bitcast<f32>(bitcast<u32>(fire[FIRE_CLAMPED].x) + 1u);
    }
}
