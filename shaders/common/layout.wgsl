// Bindings and helpers shared by every cellmd kernel.
//
// Positions are 64-bit fixed-point numbers relative to the box's lower
// corner: x − box_lo = (H + F·2⁻³²)·q per axis, with H an i32, F a u32 and
// q = 2^e a power-of-two length chosen so that the box spans at most 2²⁰·q.
// Integer arithmetic is exact and cannot be reassociated by a shader
// compiler (WGSL lets compilers rewrite float expressions as if they were
// real numbers, which defeats double-single tricks), so positions do not
// drift from the f64 CPU trajectory through rounding; only separations,
// forces and each step's displacement are f32. Periodic wrapping subtracts
// the box length L_X = L/q in the same fixed point. A particle's state
// occupies three entries of `state`: H at i, F at n + i, image counters
// (i32) at 2n + i.

struct Params {
    box_len_h: vec4<u32>,       // box edge lengths in fixed point: integer part (units of q)
    box_len_f: vec4<u32>,       // … fraction (units of q·2⁻³²)
    box_lo_h: vec4<u32>,        // lower corner in the same fixed point (unwrapped positions for externals)
    box_lo_f: vec4<u32>,
    periodic: vec4<u32>,        // 1 on periodic axes
    grid: vec4<u32>,            // cells along x, y, z; w = total cells
    cell_inv_width: vec4<f32>,  // cells per unit length
    box_len: vec4<f32>,         // box edge lengths L (f32); w = q, the fixed-point unit
    // n, nlist capacity, particle types, steps this call
    n: u32, nlist_cap: u32, n_types: u32, steps_wanted: u32,
    // (cutoff + skin)², (skin/2)², max displacement², neighbour `every`
    range2: f32, half_skin2: f32, max_disp2: f32, neighbor_every: u32,
    seed_lo: u32, seed_hi: u32, step_lo: u32, step_hi: u32,
    // neighbour `check`, scan blocks over cells, dispatch width (workgroups along x), 1 for `noise gaussian`
    neighbor_check: u32, scan_blocks: u32, groups_x: u32, gaussian: u32,
    // offsets of the sections of `topo`, then of the term force scales in `fparams`
    off_term_kind: u32, off_pair_start: u32, off_pair_terms: u32, off_bond_offsets: u32,
    off_bond_ends: u32, off_angle_offsets: u32, off_angle_slots: u32, off_ext_offsets: u32,
    off_ext_terms: u32, off_excl_offsets: u32, off_excl: u32, off_term_scale: u32,
    // offsets of the sections of `fparams`
    off_params: u32, off_skip2: u32, off_mobility: u32, off_amplitude: u32,
    // surface sections of `topo` (src/gpu/surface.rs), then their sizes
    off_faces: u32, off_body_faces: u32, off_body_term_start: u32, off_body_terms: u32,
    off_node_slot_offsets: u32, off_node_slots: u32, off_edges: u32, off_node_body: u32,
    off_node_edge_offsets: u32, off_node_edges: u32, off_node_face_offsets: u32, off_node_faces: u32,
    n_faces: u32, n_bodies: u32, n_edges: u32, n_body_nodes: u32,
    // contact between bodies (src/gpu/contact.rs): sections of `topo`, then faces, body types, d̂, ℓ², fraction ring in `surf`
    off_cfaces: u32, off_first_start: u32, off_first_faces: u32, off_corner_start: u32,
    off_corner_faces: u32, off_cbody: u32, off_cbody_type: u32, off_crule_start: u32,
    off_crule_list: u32, off_cany: u32, off_crules: u32, n_cfaces: u32,
    n_body_types: u32, contact_dhat: f32, contact_edge2: f32, off_fractions: u32,
    // bond kinetics on the device (shaders/common/kinetics.wgsl): kinetic bonds, their first term, event capacity, bond types
    kin_bonds: u32, kin_first_term: u32, kin_capacity: u32, kin_types: u32,
    // volume elements (src/gpu/tetra.rs): `topo` and `fparams` sections, their first `surf` slot, their number
    off_tetras: u32, off_tetra_rest: u32, off_tetra_slot_offsets: u32, off_tetra_slots: u32,
    tetra_surf_base: u32, n_tetras: u32, tetra_pad0: u32, tetra_pad1: u32,
    // simulated time at this call's first step (f32 high part + remainder), dt (for `sim_time`)
    time_hi: f32, time_lo: f32, dt: f32, clock_pad: f32,
    // fractional `special_bonds` partners (src/gpu/special.rs): `topo` offsets (CSR by particle), entries
    off_special_offsets: u32, off_special: u32, special_pad0: u32, special_pad1: u32,
    // area-weighted contact (src/gpu/adhesion.rs): `topo` sections (rule slots per type pair: CSR; each slot's rule), slots, then `surf` regions
    // (the contact pass's closest distances, src/gpu/contact.rs; the rules' switch values and pulls)
    off_arule_start: u32, off_arule_list: u32, off_arules: u32, n_arules: u32,
    off_closest: u32, off_aswitch: u32, off_apull: u32, adhesion_pad: u32,
    // protocols (shaders/common/protocol.wgsl): held-coordinate words present, ramped slots, the ramp table's first step, `protocol` offsets, driven indenters
    protocol_held: u32, n_ramp_slots: u32, ramp_first_lo: u32, off_movers: u32, off_ramp_slots: u32, off_ramp_table: u32, n_drives: u32, off_drives: u32,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> state: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read_write> next: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> reference: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read> topo: array<u32>;
// Read-write: ramps write their parameters' values per step (shaders/common/protocol.wgsl).
@group(0) @binding(5) var<storage, read_write> fparams: array<f32>;
@group(0) @binding(6) var<storage, read_write> cell_count: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> cell_data: array<u32>;
// The neighbour-list rows of the bound chunk of particles (src/gpu/nlist.rs):
// particle i's row starts at (i − chunk.first)·(1 + nlist_cap), its count
// first, then its neighbours. `nb_build` and `forces` run once per chunk.
@group(0) @binding(8) var<storage, read_write> nlist: array<u32>;
@group(0) @binding(9) var<storage, read_write> force: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> status: array<atomic<u32>>;
// Surface terms (shaders/common/surface.wgsl; regions in src/gpu/surface.rs).
@group(0) @binding(12) var<storage, read_write> surf: array<vec4<f32>>;
// Bond kinetics on the device (shaders/common/kinetics.wgsl; layout in src/gpu/kinetics.rs).
@group(0) @binding(13) var<storage, read_write> kin: array<atomic<u32>>;
// Protocols on the device: held coordinates, moving groups, ramps (shaders/common/protocol.wgsl).
@group(0) @binding(14) var<storage, read_write> protocol: array<u32>;

struct Chunk {
    first: u32,  // first particle of the chunk
    count: u32,  // particles in the chunk
    pad0: u32,
    pad1: u32,
}
@group(0) @binding(11) var<uniform> chunk: Chunk;

// The particle of invocation (wg, local) of a per-chunk dispatch, and
// whether it is one (the dispatch is rounded up to whole workgroups).
fn chunk_particle(wg: vec3<u32>, local: u32) -> u32 {
    return chunk.first + linear_index(wg, local);
}

fn in_chunk(i: u32) -> bool {
    return i < chunk.first + chunk.count;
}

// Start of particle i's row in the bound chunk.
fn nlist_row(i: u32) -> u32 {
    return (i - chunk.first) * (1u + P.nlist_cap);
}

// The words of `status` (ST_*, read back by the host at every
// synchronisation), the halt bits (HALT_*), NO_PARTICLE, CONTACT_ONLY and
// WORKGROUP are the prelude's (src/gpu/prelude.rs).

// Linear invocation index of a 2-D dispatch (dispatches wider than 65 535
// workgroups are split along y).
fn linear_index(wg: vec3<u32>, local: u32) -> u32 {
    return (wg.y * P.groups_x + wg.x) * WORKGROUP + local;
}

fn halted() -> bool {
    return atomicLoad(&status[ST_HALTED]) != 0u;
}

// Halted for a reason other than `own`: a kernel that raises `own` and names
// the lowest index at fault reads this, so the workgroups that run after the
// first one found still look (the host's report names the lowest, whatever
// order the workgroups ran in).
fn halted_other_than(own: u32) -> bool {
    return (atomicLoad(&status[ST_HALTED]) & ~own) != 0u;
}

// 64-bit fixed point per axis: (h, f) = h·2³² + f with h signed.
struct Fixed3 {
    h: vec3<i32>,
    f: vec3<u32>,
}

fn fixed_of(i: u32) -> Fixed3 {
    return Fixed3(bitcast<vec3<i32>>(state[i].xyz), state[P.n + i].xyz);
}

fn fixed_add(a: Fixed3, b: Fixed3) -> Fixed3 {
    let f = a.f + b.f;
    let carry = vec3<i32>(f < a.f);
    return Fixed3(a.h + b.h + carry, f);
}

fn fixed_sub(a: Fixed3, b: Fixed3) -> Fixed3 {
    let borrow = vec3<i32>(a.f < b.f);
    return Fixed3(a.h - b.h - borrow, a.f - b.f);
}

// The fixed-point number as a length (f32).
fn fixed_to_length(a: Fixed3) -> vec3<f32> {
    return (vec3<f32>(a.h) + vec3<f32>(a.f) * 2.3283064365386963e-10) * P.box_len.w;
}

fn box_fixed() -> Fixed3 {
    return Fixed3(bitcast<vec3<i32>>(P.box_len_h.xyz), P.box_len_f.xyz);
}

fn image_of(i: u32) -> vec3<i32> {
    return bitcast<vec3<i32>>(state[2u * P.n + i].xyz);
}

// Separation x_j − x_i, exact in fixed point (minimum image on periodic
// axes: the box length is subtracted or added in fixed point too), then
// rounded once to f32.
fn separation(i: u32, j: u32) -> vec3<f32> {
    return minimum_image_length(fixed_sub(fixed_of(j), fixed_of(i)));
}

// A fixed-point difference of two positions as its minimum image (exact),
// rounded once to a length.
fn minimum_image_length(difference: Fixed3) -> vec3<f32> {
    var d = difference;
    let l = box_fixed();
    let half = vec3<i32>(l.h / 2);
    let per = P.periodic.xyz == vec3<u32>(1u);
    let above = per & (d.h >= half);
    let below = per & (d.h < -half);
    let minus = fixed_sub(d, l);
    let plus = fixed_add(d, l);
    d = Fixed3(select(select(d.h, plus.h, below), minus.h, above), select(select(d.f, plus.f, below), minus.f, above));
    return fixed_to_length(d);
}

// Position relative to the box corner (f32), for cell binning.
fn relative_position(i: u32) -> vec3<f32> {
    return fixed_to_length(fixed_of(i));
}

// Unwrapped position in f32 (for external fields): box_lo + x in fixed
// point, rounded once, so a coordinate near 0 in a box from −70 keeps f32's
// precision at its own size, not at 70's (a stiff wall multiplies the
// difference: 3.8e-6 µm × 1000 pN/µm), then the images' shift.
fn unwrapped(i: u32) -> vec3<f32> {
    let lo = Fixed3(bitcast<vec3<i32>>(P.box_lo_h.xyz), P.box_lo_f.xyz);
    return fixed_to_length(fixed_add(fixed_of(i), lo)) + vec3<f32>(image_of(i)) * P.box_len.xyz;
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

// The arms of an angle at its vertex j: unit vectors û = (ri − rj)/|u|,
// v̂ = (rk − rj)/|v|, their lengths and cos θ = û·v̂.
struct AngleArms {
    uh: vec3<f32>,
    vh: vec3<f32>,
    lu: f32,
    lv: f32,
    c: f32,
}

fn angle_arms(ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> AngleArms {
    let u = ri - rj;
    let v = rk - rj;
    let lu = length(u);
    let lv = length(v);
    return AngleArms(u / lu, v / lv, lu, lv, dot(u / lu, v / lv));
}

struct OneBody {
    energy: f32,
    force: vec3<f32>,
}

const RADIAL_ZERO: Radial = Radial(0.0, 0.0);

// A body's totals for its per-face surface laws.
struct BodyTotals {
    volume: f32,
    area: f32,
    faces: f32,
}

// One face of a body: its corners relative to corner 0 (x0 = 0), its area,
// the area's gradient at each corner, and each corner's share of the
// volume's gradient, A·n̂/3 (the same for all three corners; summed over the
// faces around a node it is the node's ∂V/∂x on a closed surface).
struct FaceGeometry {
    x1: vec3<f32>,
    x2: vec3<f32>,
    area: f32,
    ga0: vec3<f32>,
    ga1: vec3<f32>,
    ga2: vec3<f32>,
    gv: vec3<f32>,
}

// What a curvature law gives for one node: its energy, ∂E/∂M_i, ∂E/∂A_i.
struct NodeCurvature {
    energy: f32,
    de_dm: f32,
    de_da: f32,
}

// What a per-face surface law gives: the face's share of the body's energy
// and the forces on its corners.
struct SurfaceFace {
    energy: f32,
    f0: vec3<f32>,
    f1: vec3<f32>,
    f2: vec3<f32>,
}

// (dE/dr)·d/r, exactly zero for a term that exerts no force (also at r = 0).
fn force_along(radial: Radial, d: vec3<f32>, r: f32) -> vec3<f32> {
    return select((radial.de_dr / r) * d, vec3<f32>(0.0), radial.de_dr == 0.0);
}
