// Bindings and helpers shared by every cellmd kernel.
//
// Positions are double-single numbers relative to the box's lower corner:
// x − box_lo = hi + lo with |lo| ≤ ulp(hi)/2 (about 48 bits of mantissa), so
// a trajectory does not drift from the f64 CPU one by f32 rounding of the
// positions; separations and forces are f32. A particle's state occupies
// three entries of `state`: hi at i, lo at n + i, image counters (bitcast
// i32) at 2n + i.

struct Params {
    box_len_hi: vec4<f32>,      // box edge lengths L (double-single high part)
    box_len_lo: vec4<f32>,      // … low part
    box_lo: vec4<f32>,          // lower corner (f32; unwrapped positions for externals)
    periodic: vec4<u32>,        // 1 on periodic axes
    grid: vec4<u32>,            // cells along x, y, z; w = total cells
    cell_inv_width: vec4<f32>,  // cells per unit length
    // n, nlist capacity, particle types, steps this call
    n: u32, nlist_cap: u32, n_types: u32, steps_wanted: u32,
    // (cutoff + skin)², (skin/2)², max displacement², neighbour `every`
    range2: f32, half_skin2: f32, max_disp2: f32, neighbor_every: u32,
    seed_lo: u32, seed_hi: u32, step_lo: u32, step_hi: u32,
    // neighbour `check`, scan blocks over cells, dispatch width (workgroups along x), unused
    neighbor_check: u32, scan_blocks: u32, groups_x: u32, pad0: u32,
    // offsets of the sections of `topo`
    off_term_kind: u32, off_pair_start: u32, off_pair_terms: u32, off_bond_offsets: u32,
    off_bond_ends: u32, off_angle_offsets: u32, off_angle_slots: u32, off_ext_offsets: u32,
    off_ext_terms: u32, off_excl_offsets: u32, off_excl: u32, pad1: u32,
    // offsets of the sections of `fparams`
    off_params: u32, off_skip2: u32, off_mobility: u32, off_amplitude: u32,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> state: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> next: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> reference: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> topo: array<u32>;
@group(0) @binding(5) var<storage, read> fparams: array<f32>;
@group(0) @binding(6) var<storage, read_write> cell_count: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> cell_data: array<u32>;
@group(0) @binding(8) var<storage, read_write> nlist: array<u32>;
@group(0) @binding(9) var<storage, read_write> force: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> status: array<atomic<u32>>;

// Words of `status` (read back by the host at every synchronisation).
const ST_HALTED: u32 = 0u;        // bit 0: neighbour list overflow, bit 1: blow-up
const ST_OVERFLOW_NEED: u32 = 1u; // largest neighbour count met (when it overflowed)
const ST_MAX_DISP2: u32 = 2u;     // bits of the largest squared displacement since the last build
const ST_BUILDS: u32 = 3u;        // neighbour-list builds so far
const ST_STEPS_DONE: u32 = 4u;    // steps completed in this call
const ST_BLOWUP_PARTICLE: u32 = 5u; // lowest particle index whose step was refused
const ST_FORCE_REBUILD: u32 = 6u; // host request: rebuild before the next step
const HALT_OVERFLOW: u32 = 1u;
const HALT_BLOWUP: u32 = 2u;

const WORKGROUP: u32 = 256u;

// Linear invocation index of a 2-D dispatch (dispatches wider than 65 535
// workgroups are split along y).
fn linear_index(wg: vec3<u32>, local: u32) -> u32 {
    return (wg.y * P.groups_x + wg.x) * WORKGROUP + local;
}

fn halted() -> bool {
    return atomicLoad(&status[ST_HALTED]) != 0u;
}

// Error-free sum of two f32: s + e = a + b exactly (Knuth's two-sum).
fn two_sum(a: f32, b: f32) -> vec2<f32> {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    return vec2<f32>(s, e);
}

// (hi, lo) + (b_hi, b_lo), renormalised.
fn ds_add(a_hi: f32, a_lo: f32, b_hi: f32, b_lo: f32) -> vec2<f32> {
    let s = two_sum(a_hi, b_hi);
    let e = s.y + a_lo + b_lo;
    let hi = s.x + e;
    return vec2<f32>(hi, e - (hi - s.x));
}

fn image_of(i: u32) -> vec3<i32> {
    return bitcast<vec3<i32>>(state[2u * P.n + i].xyz);
}

// Separation x_j − x_i by the minimum image on periodic axes, from the
// double-single positions (the high parts cancel exactly for close pairs).
fn separation(i: u32, j: u32) -> vec3<f32> {
    let hi_i = state[i].xyz;
    let hi_j = state[j].xyz;
    let lo_i = state[P.n + i].xyz;
    let lo_j = state[P.n + j].xyz;
    let per = vec3<f32>(P.periodic.xyz);
    let shift = round((hi_j - hi_i) / P.box_len_hi.xyz) * per;
    return ((hi_j - shift * P.box_len_hi.xyz) - hi_i) + ((lo_j - shift * P.box_len_lo.xyz) - lo_i);
}

// Unwrapped position in f32 (for external fields).
fn unwrapped(i: u32) -> vec3<f32> {
    let img = vec3<f32>(image_of(i));
    return P.box_lo.xyz + (state[i].xyz + img * P.box_len_hi.xyz) + (state[P.n + i].xyz + img * P.box_len_lo.xyz);
}

// Parameters of a force-field term (eight slots, in schema order).
fn term_params(term: u32) -> array<f32, 8> {
    var p: array<f32, 8>;
    let base = P.off_params + 8u * term;
    for (var k = 0u; k < 8u; k++) {
        p[k] = fparams[base + k];
    }
    return p;
}

struct Radial {
    energy: f32,
    de_dr: f32, // positive when the pair pulls together (tension)
}

struct ThreeBody {
    energy: f32,
    fi: vec3<f32>,
    fj: vec3<f32>,
    fk: vec3<f32>,
}

struct OneBody {
    energy: f32,
    force: vec3<f32>,
}

const RADIAL_ZERO: Radial = Radial(0.0, 0.0);
