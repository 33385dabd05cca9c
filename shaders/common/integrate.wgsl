// Overdamped Euler–Maruyama, as src/integrate/overdamped.rs:
//   x ← x + dt·F/γ + √(2·kT·dt/γ)·ξ
// with dt/γ and the noise amplitude per particle type precomputed in f64 by
// the host (both 0 for a `fixed` type), ξ from the counter-based Philox
// stream keyed by (seed, step, particle). The new position goes to `next`;
// `commit` copies it back only if no particle's step was refused (non-finite,
// or longer than max_displacement), so a blow-up keeps the last good state.
// A refused step only lowers ST_BLOWUP_PARTICLE; `commit`, the next
// dispatch, raises HALT_BLOWUP. Raised here, it would stop the workgroups
// that had not run yet (they return on `halted()`), and the particle named
// would be the lowest refused among those that ran first, not the lowest.

fn current_step() -> vec2<u32> {
    let done = atomicLoad(&status[ST_STEPS_DONE]);
    let lo = P.step_lo + done;
    return vec2<u32>(lo, P.step_hi + select(0u, 1u, lo < P.step_lo));
}

// The simulated time at the start of the current step, as the CPU's clock:
// the call's start time (two f32 words, host-computed in f64) plus the
// fractions of dt the steps done in this call took (`advance` sums them; each
// is 1 unless the contact clamp shortened the step) times dt (externals with
// expression parameters and velocity fields of moved groups read it).
fn sim_time() -> f32 {
    return P.time_hi + (P.time_lo + bitcast<f32>(atomicLoad(&status[ST_ELAPSED])) * P.dt);
}

// Particle i's drift dt·F/γ.
fn drift(i: u32) -> vec3<f32> {
    return free_axes(i) * force[i].xyz * fparams[P.off_mobility + topo[i]];
}

// Particle i's noise √(2kT·dt/γ)·ξ of this step.
fn noise(i: u32) -> vec3<f32> {
    let amplitude = fparams[P.off_amplitude + topo[i]];
    if amplitude == 0.0 {
        return vec3<f32>(0.0);
    }
    return amplitude * unit_noise(i);
}

// Particle i's ξ of this step (unit variance per axis; the implicit step
// scales it too, shaders/common/implicit.wgsl).
fn unit_noise(i: u32) -> vec3<f32> {
    let seed = vec2<u32>(P.seed_lo, P.seed_hi);
    if P.gaussian == 1u {
        return gaussian3(seed, current_step(), i);
    }
    return noise3(seed, current_step(), i);
}

// A displacement in fixed point: q is a power of two, so |dx|/q is exact
// in f32 and splits exactly into an integer and a 32-bit fraction (bits
// below q·2⁻³² of very small steps are dropped: < 1e-15 of the box); the
// sign is applied in fixed point, so no rounding depends on it.
fn fixed_of_length(dx: vec3<f32>) -> Fixed3 {
    let v = abs(dx) / P.box_len.w;
    let whole = floor(v);
    let magnitude = Fixed3(vec3<i32>(whole), vec3<u32>((v - whole) * 4294967296.0));
    let negated = fixed_sub(Fixed3(vec3<i32>(0), vec3<u32>(0u)), magnitude);
    let negative = dx < vec3<f32>(0.0);
    return Fixed3(select(magnitude.h, negated.h, negative), select(magnitude.f, negated.f, negative));
}

// A position and its image counters; `ok` false: the step is refused.
struct Placed {
    x: Fixed3,
    img: vec3<i32>,
    ok: bool,
}

// Wraps x into the box on periodic axes (in fixed point), counting images.
fn wrap_into_box(x0: Fixed3, img0: vec3<i32>) -> Placed {
    var x = x0;
    let l = box_fixed();
    let zero = vec3<i32>(0);
    let per = P.periodic.xyz == vec3<u32>(1u);
    let from_top = fixed_sub(x, l);
    let wrap_down = per & (from_top.h >= zero); // x ≥ L
    let wrap_up = per & (x.h < zero); // x < 0
    let from_bottom = fixed_add(x, l);
    x = Fixed3(select(select(x.h, from_bottom.h, wrap_up), from_top.h, wrap_down), select(select(x.f, from_bottom.f, wrap_up), from_top.f, wrap_down));
    return Placed(x, img0 + vec3<i32>(wrap_down) - vec3<i32>(wrap_up), true);
}

// The step takes s·dt (s < 1 only where the contact step clamp shortened
// it, src/gpu/contact.rs): drift s·a, noise √s·b (exactly a + b at s = 1).
@compute @workgroup_size(256)
fn integrate(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    let s = bitcast<f32>(atomicLoad(&status[ST_FRACTION]));
    step_particle(i, s * drift(i) + sqrt(s) * noise(i));
}

// Moves particle i by dx into `next` (the implicit step's move too), or
// refuses the step: non-finite, or longer than max_displacement.
fn step_particle(i: u32, dx: vec3<f32>) {
    let d2 = dot(dx, dx);
    if !(d2 <= P.max_disp2) {
        atomicMin(&status[ST_BLOWUP_PARTICLE], i);
        return;
    }
    let placed = prescribe(i, wrap_into_box(fixed_add(fixed_of(i), fixed_of_length(dx)), image_of(i)));
    if !placed.ok {
        atomicMin(&status[ST_BLOWUP_PARTICLE], i);
        return;
    }
    let x = placed.x;
    let img = placed.img;
    next[i] = vec4<u32>(bitcast<vec3<u32>>(x.h), 0u);
    next[P.n + i] = vec4<u32>(x.f, 0u);
    next[2u * P.n + i] = vec4<u32>(bitcast<vec3<u32>>(img), 0u);
}

@compute @workgroup_size(256)
fn commit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    if atomicLoad(&status[ST_BLOWUP_PARTICLE]) != NO_PARTICLE {
        atomicOr(&status[ST_HALTED], HALT_BLOWUP);
        return;
    }
    state[i] = next[i];
    state[P.n + i] = next[P.n + i];
    state[2u * P.n + i] = next[2u * P.n + i];
}

// Counts the step and adds its fraction s to the call's elapsed fractions
// (`sim_time`); with contact, records s in the ring the host reads
// (src/gpu/contact.rs); resets s to 1 for the next step.
@compute @workgroup_size(1)
fn advance() {
    if !halted() {
        let done = atomicAdd(&status[ST_STEPS_DONE], 1u);
        if P.n_cfaces > 0u {
            surf[P.off_fractions + done % FRACTION_SLOTS] = vec4<f32>(bitcast<f32>(atomicLoad(&status[ST_FRACTION])), 0.0, 0.0, 0.0);
        }
        let elapsed = bitcast<f32>(atomicLoad(&status[ST_ELAPSED])) + bitcast<f32>(atomicLoad(&status[ST_FRACTION]));
        atomicStore(&status[ST_ELAPSED], bitcast<u32>(elapsed));
        atomicStore(&status[ST_FRACTION], 0x3f800000u);
    }
}
