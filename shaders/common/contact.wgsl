// Node–face contact between bodies and the step clamp (the pass order, the
// equations and the determinism argument: src/gpu/contact.rs). One
// invocation per contact node, dispatched per neighbour-list chunk after
// `forces`; `contact_law` dispatches on the registry index of the rule's
// interaction type to `NAME_contact` (shaders/interactions/NAME.wgsl).

const NO_BODY: u32 = 0xffffffffu;
const CONTACT_RULE_WORDS: u32 = 9u;
// The step clamp: a particle moves at most this fraction of its closest contact distance.
const STEP_FRACTION: f32 = 0.4;
// Entries of the ring of step fractions in `surf` (FRACTION_SLOTS in src/gpu/contact.rs).
const FRACTION_SLOTS: u32 = 1024u;

fn contact_body(i: u32) -> u32 {
    return topo[P.off_cbody + i];
}

// Word k of contact face f: corners 0–2 (particles), 3 its packed body.
fn contact_face(f: u32, k: u32) -> u32 {
    return topo[P.off_cfaces + 4u * f + k];
}

// The (node body type, face body type) index of the rule tables.
fn contact_types(node_body: u32, face_body: u32) -> u32 {
    return topo[P.off_cbody_type + node_body] * P.n_body_types + topo[P.off_cbody_type + face_body];
}

fn contact_rule_params(rule: u32) -> array<f32, 8> {
    var p: array<f32, 8>;
    let base = P.off_crules + CONTACT_RULE_WORDS * rule + 1u;
    for (var k = 0u; k < 8u; k++) {
        p[k] = bitcast<f32>(topo[base + k]);
    }
    return p;
}

// b(d) summed over the node–face rules of type pair `types`, in rule order.
fn contact_radial(types: u32, d: f32) -> Radial {
    var out = RADIAL_ZERO;
    let end = topo[P.off_crule_start + types + 1u];
    for (var q = topo[P.off_crule_start + types]; q < end; q++) {
        let rule = topo[P.off_crule_list + q];
        let b = contact_law(topo[P.off_crules + CONTACT_RULE_WORDS * rule], contact_rule_params(rule), d);
        out.energy += b.energy;
        out.de_dr += b.de_dr;
    }
    return out;
}

// Barycentric weights of the point of triangle (a, b, c) closest to p, by
// Voronoi region (src/mesh.rs, `closest_weights`).
fn closest_weights(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    let bp = p - b;
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return vec3<f32>(0.0, 1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return vec3<f32>(1.0 - v, v, 0.0);
    }
    let cp = p - c;
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return vec3<f32>(1.0 - w, 0.0, w);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return vec3<f32>(0.0, 1.0 - w, w);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    return vec3<f32>(1.0 - v - w, v, w);
}

// Node k against face f: the distance d, the weights w of the closest
// point and the unit normal n̂ from it to the node. Computed relative to the
// face's first corner, so every participant gets the same bits.
struct ContactPair {
    d: f32,
    w: vec3<f32>,
    n: vec3<f32>,
}

fn contact_pair(k: u32, f: u32) -> ContactPair {
    let a = contact_face(f, 0u);
    let p = separation(a, k);
    let b = separation(a, contact_face(f, 1u));
    let c = separation(a, contact_face(f, 2u));
    let w = closest_weights(p, vec3<f32>(0.0), b, c);
    let gap = p - (w.y * b + w.z * c);
    let d = length(gap);
    return ContactPair(d, w, gap / d);
}

// Whether an edge of face f is longer than the contact search covers.
fn face_outgrew_search(f: u32) -> bool {
    let a = contact_face(f, 0u);
    let b = separation(a, contact_face(f, 1u));
    let c = separation(a, contact_face(f, 2u));
    let bc = c - b;
    return max(max(dot(b, b), dot(c, c)), dot(bc, bc)) > P.contact_edge2;
}

// Faces of one corner tested per walk of its neighbour list.
const CORNER_BATCH: u32 = 8u;

// Up to CORNER_BATCH faces of corner i, its face slots from `first` to `end`
// (face·4 + role), each with its bounding sphere relative to i: a node within
// d̂ of the face is within d̂ + r of its centre c. The test only skips pairs
// farther than d̂ (zero force, above the clamp's cap), with a margin of 1e-3
// for f32 rounding.
struct CornerBatch {
    count: u32,
    slots: array<u32, CORNER_BATCH>,
    centres: array<vec3<f32>, CORNER_BATCH>,
    reach2: array<f32, CORNER_BATCH>,
}

fn corner_batch(i: u32, first: u32, end: u32) -> CornerBatch {
    var out: CornerBatch;
    out.count = min(end - first, CORNER_BATCH);
    for (var q = 0u; q < out.count; q++) {
        let slot = topo[P.off_corner_faces + first + q];
        let face = slot / 4u;
        let xa = separation(i, contact_face(face, 0u));
        let xb = separation(i, contact_face(face, 1u));
        let xc = separation(i, contact_face(face, 2u));
        let centre = (xa + xb + xc) / 3.0;
        let radius2 = max(max(dot(xa - centre, xa - centre), dot(xb - centre, xb - centre)), dot(xc - centre, xc - centre));
        let reach = 1.001 * (P.contact_dhat + sqrt(radius2));
        out.slots[q] = slot;
        out.centres[q] = centre;
        out.reach2[q] = reach * reach;
    }
    return out;
}

// Whether a node at x (relative to the batch's corner) may be within d̂ of face q of the batch.
fn batch_reaches(batch: ptr<function, CornerBatch>, q: u32, x: vec3<f32>) -> bool {
    let off_centre = x - (*batch).centres[q];
    return dot(off_centre, off_centre) < (*batch).reach2[q];
}

// The largest s ∈ (0, 1] with s·a + √s·b ≤ limit (src/integrate/overdamped.rs, `step_fraction`).
fn contact_step_fraction(a: f32, b: f32, limit: f32) -> f32 {
    if a + b <= limit {
        return 1.0;
    }
    let u = 2.0 * limit / (b + sqrt(b * b + 4.0 * a * limit));
    return u * u;
}

// What the faces near node i do to it (the node part of the contact pass):
// the node–face terms' force and energy, and its closest face distance
// (at most d̂); with `track`, each area-weighted rule's nearest face too
// (shaders/common/adhesion.wgsl).
struct ContactNode {
    f: vec3<f32>,
    e: f32,
    closest: f32,
}

fn contact_node_part(i: u32, body: u32, track: bool) -> ContactNode {
    var out = ContactNode(vec3<f32>(0.0), 0.0, P.contact_dhat);
    let row = nlist_row(i);
    let count = min(nlist[row], P.nlist_cap);
    // The faces whose first corner is a neighbour of another body (the
    // list holds those first, shaders/common/neighbor.wgsl).
    for (var k = 0u; k < count; k++) {
        let j = nlist[row + 1u + k] & ~CONTACT_ONLY;
        let other = contact_body(j);
        if other == NO_BODY || other == body {
            break;
        }
        let types = contact_types(body, other);
        if topo[P.off_cany + types] == 0u {
            continue;
        }
        let faces_end = topo[P.off_first_start + j + 1u];
        for (var q = topo[P.off_first_start + j]; q < faces_end; q++) {
            let face = topo[P.off_first_faces + q];
            let pair = contact_pair(i, face);
            out.closest = min(out.closest, pair.d);
            let b = contact_radial(types, pair.d);
            if b.de_dr != 0.0 {
                out.f -= b.de_dr * pair.n;
                out.e += b.energy;
            }
            if track && pair.d < P.contact_dhat {
                adhesion_track(i, types, face, pair.d);
            }
        }
    }
    return out;
}

@compute @workgroup_size(256)
fn contact_forces(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = chunk_particle(wg, local);
    if !in_chunk(i) || halted() {
        return;
    }
    let body = contact_body(i);
    if body == NO_BODY {
        return;
    }
    // As a node (with area-weighted rules: done by `adhesion_nodes`, which
    // left the closest distance), then its own adhesion forces.
    var part = ContactNode(vec3<f32>(0.0), 0.0, 0.0);
    if P.n_arules == 0u {
        part = contact_node_part(i, body, false);
    } else {
        let own = adhesion_own(i);
        part = ContactNode(own.xyz, own.w, surf[adhesion_closest(i)].x);
    }
    var f = part.f;
    var e = part.e;
    var closest = part.closest;
    let row = nlist_row(i);
    let count = min(nlist[row], P.nlist_cap);
    // As a corner: its faces against the neighbours of other bodies, up to
    // CORNER_BATCH faces per walk of the neighbour list (one walk for a mesh
    // node's 5–6 faces).
    let corner_start = topo[P.off_corner_start + i];
    let corner_end = topo[P.off_corner_start + i + 1u];
    for (var q = corner_start; q < corner_end; q++) {
        let slot = topo[P.off_corner_faces + q];
        if slot % 4u == 0u && face_outgrew_search(slot / 4u) {
            atomicOr(&status[ST_HALTED], HALT_REACH);
        }
    }
    for (var first = corner_start; first < corner_end; first += CORNER_BATCH) {
        var batch = corner_batch(i, first, corner_end);
        for (var k = 0u; k < count; k++) {
            let node = nlist[row + 1u + k] & ~CONTACT_ONLY;
            let other = contact_body(node);
            if other == NO_BODY || other == body {
                break; // the other bodies' nodes come first in the list
            }
            let types = contact_types(other, body);
            if topo[P.off_cany + types] == 0u {
                continue;
            }
            let x = separation(i, node);
            for (var q = 0u; q < batch.count; q++) {
                if !batch_reaches(&batch, q, x) {
                    continue;
                }
                let face = batch.slots[q] / 4u;
                let role = batch.slots[q] % 4u;
                let pair = contact_pair(node, face);
                closest = min(closest, pair.d);
                let b = contact_radial(types, pair.d);
                if b.de_dr != 0.0 {
                    f += b.de_dr * pair.w[role] * pair.n;
                }
                if P.n_arules > 0u {
                    f += adhesion_corner(node, face, role, types, pair);
                }
            }
        }
    }
    let total = force[i] + vec4<f32>(f, e);
    force[i] = total;
    // The step clamp: this particle's largest s, min-reduced through the bits.
    let s = contact_step_fraction(length(drift(i)), length(noise(i)), STEP_FRACTION * closest);
    atomicMin(&status[ST_FRACTION], bitcast<u32>(s));
}
