// Protocols on the device (src/gpu/protocol.rs; the CPU's are src/run/protocol.rs).
//
// `protocol` (binding 14) holds, when the run has held coordinates, one word
// per particle at 0: bits 0–2 the held axes (`freeze`, or all three for a
// moved particle), bits 3… the moving group + 1 (0: none). Each moving group
// has 8 words at P.off_movers + 8m: its step v·dt in fixed point (high words
// 0–2, low words 3–5, computed in f64 by the host) and word 6, 1 when its
// velocity is a field of x, y, z, t (`mover_velocity`, generated). Ramped
// parameters: P.n_ramp_slots `fparams` indices at P.off_ramp_slots, then a
// table of their values (f32, rounded from the CPU's f64 values), one row per
// step from step P.ramp_first_lo, at P.off_ramp_table.

// The free axes of particle i (1: free, 0: held): a held coordinate takes no
// drift (the CPU masks its force), while its noise still counts in the contact
// clamp and the blow-up check, as on the CPU.
fn free_axes(i: u32) -> vec3<f32> {
    if P.protocol_held == 0u {
        return vec3<f32>(1.0);
    }
    let word = protocol[i];
    return select(vec3<f32>(1.0), vec3<f32>(0.0), (vec3<u32>(word) & vec3<u32>(1u, 2u, 4u)) != vec3<u32>(0u));
}

// After the integrator's step of particle i to `p`: its held axes go back
// where they were (position and image), and a moved particle advances by its
// group's v·dt (v at its position before the step and the step's start time),
// wrapped into the box. `ok` is false where a velocity field is not finite.
fn prescribe(i: u32, p: Placed) -> Placed {
    if P.protocol_held == 0u {
        return p;
    }
    let word = protocol[i];
    if word == 0u {
        return p;
    }
    let held = (vec3<u32>(word) & vec3<u32>(1u, 2u, 4u)) != vec3<u32>(0u);
    let old = fixed_of(i);
    let x = Fixed3(select(p.x.h, old.h, held), select(p.x.f, old.f, held));
    let img = select(p.img, image_of(i), held);
    let mover = word >> 3u;
    if mover == 0u {
        return Placed(x, img, true);
    }
    let base = P.off_movers + 8u * (mover - 1u);
    var step = Fixed3(bitcast<vec3<i32>>(vec3<u32>(protocol[base], protocol[base + 1u], protocol[base + 2u])), vec3<u32>(protocol[base + 3u], protocol[base + 4u], protocol[base + 5u]));
    if protocol[base + 6u] == 1u {
        let d = mover_velocity(mover - 1u, unwrapped(i), sim_time()) * P.dt;
        if !(dot(d, d) < 1e36) {
            return Placed(x, img, false);
        }
        step = fixed_of_length(d);
    }
    return wrap_into_box(fixed_add(x, step), img);
}

// Writes every ramped parameter's value at the current step into `fparams`
// (before the step's force passes).
@compute @workgroup_size(256)
fn protocol_ramps(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let r = linear_index(wg, local);
    if r >= P.n_ramp_slots || halted() {
        return;
    }
    let row = current_step().x - P.ramp_first_lo;
    fparams[protocol[P.off_ramp_slots + r]] = bitcast<f32>(protocol[P.off_ramp_table + row * P.n_ramp_slots + r]);
}

// Driven indenters (`indent`): P.n_drives records of 16 words from
// P.off_drives: 0 the external's term, 1–2 its members' range in `protocol`,
// 3 holding (the load was reached), 4 advances in this call, 5 1 with a
// target load, 6 the load (f32 bits), 7–9 the `fparams` slots of the centre
// x, y, z, 10 the offset of its table of centres (3 f32 per advance, from
// the centre at the call's start; host-computed in f64 as the CPU's sums).
var<workgroup> drive_load: array<vec3<f32>, 256>;

// After the step's forces: each driven indenter's load, the magnitude of the
// summed force it exerts on its members (strided partial sums, then a tree
// in workgroup memory: a fixed order, so the same bits every run); a drive
// whose load reached its target holds from now on.
@compute @workgroup_size(256)
fn protocol_drive_check(@builtin(local_invocation_index) local: u32) {
    for (var d = 0u; d < P.n_drives; d++) {
        let base = P.off_drives + DRIVE_WORDS * d;
        let term = protocol[base];
        let kind = topo[P.off_term_kind + term];
        let p = term_params(term);
        var f = vec3<f32>(0.0);
        for (var k = protocol[base + 1u] + local; k < protocol[base + 2u]; k += WORKGROUP) {
            f += one_body_law(kind, p, unwrapped(protocol[k])).force;
        }
        drive_load[local] = f;
        workgroupBarrier();
        for (var width = WORKGROUP / 2u; width > 0u; width /= 2u) {
            if local < width {
                drive_load[local] += drive_load[local + width];
            }
            workgroupBarrier();
        }
        if local == 0u && protocol[base + 5u] == 1u && length(drive_load[0]) >= bitcast<f32>(protocol[base + 6u]) {
            protocol[base + 3u] = 1u;
        }
        workgroupBarrier();
    }
}

// After the step: every drive still moving advances its centre by v·dt (the
// next row of its table).
@compute @workgroup_size(1)
fn protocol_drive_advance() {
    if halted() {
        return;
    }
    for (var d = 0u; d < P.n_drives; d++) {
        let base = P.off_drives + DRIVE_WORDS * d;
        if protocol[base + 3u] == 0u {
            let a = protocol[base + 4u] + 1u;
            protocol[base + 4u] = a;
            for (var axis = 0u; axis < 3u; axis++) {
                fparams[protocol[base + 7u + axis]] = bitcast<f32>(protocol[protocol[base + 10u] + 3u * a + axis]);
            }
        }
    }
}
