// Inextensible bonds (`constrain`) on the device: overdamped SHAKE after
// the step, as src/integrate/constraints.rs (the equation and its
// reference are there; the packing and the precision in src/gpu/shake.rs).
// Between `integrate` and `commit`:
//   1. `shake_solve` (ONE workgroup): sweeps over the constraints, colour by
//      colour (no two constraints of a colour share a particle, so a
//      colour's corrections are independent and run in parallel; colours in
//      a fixed order), each constraint moving its ends in fixed point along
//      its direction before the step, weighted by their mobilities dt/γ,
//        g = (|r|² − r0²) / (2·(w_i + w_j)·r·r_before),
//        x_i += g·w_i·r_before,   x_j −= g·w_j·r_before,
//      until every |r − r0|/r0 measured in a sweep is within the tolerance.
//      Every sweep corrects every constraint, also those already within the
//      tolerance (the CPU skips them, but its tolerance, 1e-10, is below any
//      step's stretch, so it corrects nearly every one too): the sweep that
//      finds them all within the tolerance leaves them at the f32 floor, not
//      at the tolerance, and the tension of each step is measured to that
//      floor, not to the tolerance over the step's stretch.
//      Each constraint's tension Σg·|r_before| (w carries dt, so this is the
//      CPU's Σg·|r_before|/dt) goes to `shake_out`; a projection that does
//      not converge within the sweep cap halts the run before `commit`.
//   2. `shake_place` (one per constrained particle): wraps the shaken
//      position into the box and gives the protocols' held coordinates back
//      (`prescribe`), as the CPU's protocols do after its projection.
// No float atomics: the same run gives the same bits.

@group(1) @binding(3) var<storage, read> shake_topo: array<u32>;
@group(1) @binding(4) var<storage, read_write> shake_out: array<f32>;

// The header words of `shake_topo` (SH_*, src/gpu/shake.rs writes them) are the prelude's (src/gpu/prelude.rs).

var<workgroup> shake_flag: u32;
var<workgroup> shake_limits: vec2<u32>;
var<workgroup> shake_worst: array<f32, 256>;
var<workgroup> shake_which: array<u32, 256>;
var<workgroup> shake_sweep_worst: f32;

fn next_fixed(i: u32) -> Fixed3 {
    return Fixed3(bitcast<vec3<i32>>(next[i].xyz), next[P.n + i].xyz);
}

fn set_next_fixed(i: u32, x: Fixed3) {
    next[i] = vec4<u32>(bitcast<vec3<u32>>(x.h), 0u);
    next[P.n + i] = vec4<u32>(x.f, 0u);
}

// Record c's relative length error at the shaken positions.
fn shake_error(c: u32) -> f32 {
    let at = shake_topo[SH_OFF_RECORDS] + 4u * c;
    let i = shake_topo[at];
    let j = shake_topo[at + 1u];
    let r0 = bitcast<f32>(shake_topo[at + 2u]);
    let r = minimum_image_length(fixed_sub(next_fixed(j), next_fixed(i)));
    return abs((length(r) - r0) / r0);
}

// The larger of two (error, list index) pairs; ties go to the lower index,
// as the CPU's sweep in list order keeps the first largest.
fn shake_keep(local: u32, error: f32, index: u32) {
    if error > shake_worst[local] || (error == shake_worst[local] && index < shake_which[local]) {
        shake_worst[local] = error;
        shake_which[local] = index;
    }
}

@compute @workgroup_size(256)
fn shake_solve(@builtin(local_invocation_index) local: u32) {
    if local == 0u {
        // A refused step (`commit` halts on it) is not projected.
        let refused = atomicLoad(&status[ST_BLOWUP_PARTICLE]) != NO_PARTICLE;
        shake_flag = select(atomicLoad(&status[ST_HALTED]), 1u, refused);
        shake_limits = vec2<u32>(shake_topo[SH_MAX_SWEEPS], shake_topo[SH_TOLERANCE]);
    }
    if workgroupUniformLoad(&shake_flag) != 0u {
        return;
    }
    let limits = workgroupUniformLoad(&shake_limits);
    let tolerance = bitcast<f32>(limits.y);
    let count = shake_topo[SH_COUNT];
    let color_start = shake_topo[SH_OFF_COLOR_START];
    let records = shake_topo[SH_OFF_RECORDS];
    for (var c = local; c < count; c += WORKGROUP) {
        shake_out[c] = 0.0;
    }
    var sweeps = 0u;
    loop {
        shake_worst[local] = -1.0;
        shake_which[local] = 0xffffffffu;
        for (var color = 0u; color < shake_topo[SH_COLORS]; color++) {
            for (var c = shake_topo[color_start + color] + local; c < shake_topo[color_start + color + 1u]; c += WORKGROUP) {
                let at = records + 4u * c;
                let i = shake_topo[at];
                let j = shake_topo[at + 1u];
                let r0 = bitcast<f32>(shake_topo[at + 2u]);
                let index = shake_topo[at + 3u];
                let xi = next_fixed(i);
                let xj = next_fixed(j);
                let r = minimum_image_length(fixed_sub(xj, xi));
                let error = abs((length(r) - r0) / r0);
                shake_keep(local, error, index);
                let wi = fparams[P.off_mobility + topo[i]];
                let wj = fparams[P.off_mobility + topo[j]];
                let before = separation(i, j);
                let along = dot(r, before);
                if wi + wj == 0.0 || along == 0.0 {
                    continue;
                }
                let g = (dot(r, r) - r0 * r0) / (2.0 * (wi + wj) * along);
                set_next_fixed(i, fixed_add(xi, fixed_of_length(g * wi * before)));
                set_next_fixed(j, fixed_add(xj, fixed_of_length(-g * wj * before)));
                shake_out[index] += g * length(before);
            }
            storageBarrier();
            workgroupBarrier();
        }
        // The sweep's largest error (a fixed tree: the same index every run).
        for (var width = WORKGROUP / 2u; width > 0u; width = width >> 1u) {
            if local < width {
                shake_keep(local, shake_worst[local + width], shake_which[local + width]);
            }
            workgroupBarrier();
        }
        if local == 0u {
            shake_sweep_worst = shake_worst[0];
        }
        sweeps += 1u;
        let worst = workgroupUniformLoad(&shake_sweep_worst);
        if worst <= tolerance || sweeps >= max(limits.x, 1u) {
            break;
        }
    }
    if local == 0u {
        // Not converged: the last sweep's worst constraint, re-measured after
        // its correction, halts the run if it is still out of tolerance.
        let report = count;
        var failed = 0u;
        var error = shake_worst[0];
        if shake_worst[0] > tolerance {
            var c = 0u;
            while shake_topo[records + 4u * c + 3u] != shake_which[0] {
                c += 1u;
            }
            error = shake_error(c);
            failed = select(0u, 1u, error > tolerance);
        }
        shake_out[report] = bitcast<f32>(sweeps);
        shake_out[report + 1u] = error;
        shake_out[report + 2u] = bitcast<f32>(shake_which[0]);
        if failed == 1u {
            atomicOr(&status[ST_HALTED], HALT_CONSTRAINT);
        }
    }
}

@compute @workgroup_size(256)
fn shake_place(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = linear_index(wg, local);
    if k >= shake_topo[SH_PARTICLES] || halted() || atomicLoad(&status[ST_BLOWUP_PARTICLE]) != NO_PARTICLE {
        return;
    }
    let i = shake_topo[shake_topo[SH_OFF_PARTICLES] + k];
    let img = bitcast<vec3<i32>>(next[2u * P.n + i].xyz);
    let placed = prescribe(i, wrap_into_box(next_fixed(i), img));
    if !placed.ok {
        atomicMin(&status[ST_BLOWUP_PARTICLE], i);
        return;
    }
    set_next_fixed(i, placed.x);
    next[2u * P.n + i] = vec4<u32>(bitcast<vec3<u32>>(placed.img), 0u);
}
