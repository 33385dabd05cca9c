// Overdamped Euler–Maruyama, as src/integrate/overdamped.rs:
//   x ← x + dt·F/γ + √(2·kT·dt/γ)·ξ
// with dt/γ and the noise amplitude per particle type precomputed in f64 by
// the host (both 0 for a `fixed` type), ξ from the counter-based Philox
// stream keyed by (seed, step, particle). The new position goes to `next`;
// `commit` copies it back only if no particle's step was refused (non-finite,
// or longer than max_displacement), so a blow-up keeps the last good state.

fn current_step() -> vec2<u32> {
    let done = atomicLoad(&status[ST_STEPS_DONE]);
    let lo = P.step_lo + done;
    return vec2<u32>(lo, P.step_hi + select(0u, 1u, lo < P.step_lo));
}

@compute @workgroup_size(256)
fn integrate(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    let t = topo[i];
    var dx = force[i].xyz * fparams[P.off_mobility + t];
    let amplitude = fparams[P.off_amplitude + t];
    if amplitude > 0.0 {
        dx += amplitude * noise3(vec2<u32>(P.seed_lo, P.seed_hi), current_step(), i);
    }
    let d2 = dot(dx, dx);
    if !(d2 <= P.max_disp2) {
        atomicMin(&status[ST_BLOWUP_PARTICLE], i);
        atomicOr(&status[ST_HALTED], HALT_BLOWUP);
        return;
    }
    var hi = state[i].xyz;
    var lo = state[P.n + i].xyz;
    var img = image_of(i);
    for (var a = 0u; a < 3u; a++) {
        var x = ds_add(hi[a], lo[a], dx[a], 0.0);
        if P.periodic[a] == 1u {
            if x.x + x.y >= P.box_len_hi[a] + P.box_len_lo[a] {
                x = ds_add(x.x, x.y, -P.box_len_hi[a], -P.box_len_lo[a]);
                img[a] += 1;
            } else if x.x + x.y < 0.0 {
                x = ds_add(x.x, x.y, P.box_len_hi[a], P.box_len_lo[a]);
                img[a] -= 1;
            }
        }
        hi[a] = x.x;
        lo[a] = x.y;
    }
    next[i] = vec4<f32>(hi, 0.0);
    next[P.n + i] = vec4<f32>(lo, 0.0);
    next[2u * P.n + i] = vec4<f32>(bitcast<vec3<f32>>(img), 0.0);
}

@compute @workgroup_size(256)
fn commit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    state[i] = next[i];
    state[P.n + i] = next[P.n + i];
    state[2u * P.n + i] = next[2u * P.n + i];
}

@compute @workgroup_size(1)
fn advance() {
    if !halted() {
        atomicAdd(&status[ST_STEPS_DONE], 1u);
    }
}
