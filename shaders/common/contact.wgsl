// Node–face contact between bodies and the step clamp (the pass order, the
// equations and the determinism argument: src/gpu/contact.rs). One
// invocation per contact node, dispatched per neighbour-list chunk after
// `forces`; `contact_law` dispatches on the registry index of the rule's
// interaction type to `NAME_contact` (shaders/interactions/NAME.wgsl).

// STEP_FRACTION (the step clamp: a particle moves at most this fraction of its
// closest contact distance), FRACTION_SLOTS (the ring of step fractions in
// `surf`), CONTACT_RULE_WORDS and NO_BODY are the prelude's (src/gpu/prelude.rs).

// Where particle i's closest contact distance lives in `surf` (x): written by
// the contact pass (its node part first, with area-weighted rules), read by
// FIRE's step clamp.
fn contact_closest(i: u32) -> u32 {
    return P.off_closest + i;
}

// The largest fraction s ≤ 1 of a move dx that particle i may take under the
// contact step clamp of a move with no noise part (FIRE, the implicit step;
// src/integrate/overdamped.rs, `clamp_fraction`): L_i/|dx| where |dx| exceeds
// L_i = 0.4 × its closest contact distance, else 1 (also for particles of no
// contact body).
fn contact_move_fraction(i: u32, dx: vec3<f32>) -> f32 {
    if contact_body(i) == NO_BODY {
        return 1.0;
    }
    let limit = STEP_FRACTION * surf[contact_closest(i)].x;
    let moved = length(dx);
    return select(1.0, limit / moved, moved > limit);
}

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

// The node–face pairs of particle i as a node, one per `next_node_pair`
// (false when done): the faces (CSR by first corner, in face order) of each
// node of another body in its row, in row order, where a contact rule acts
// between the two bodies' types. The list holds the other bodies' nodes
// first (shaders/common/neighbor.wgsl), so the walk stops at the first entry
// that is not one. The force pass and the implicit step's products walk alike.
struct NodeWalk {
    body: u32,
    row: u32,
    count: u32,
    k: u32,     // the next row entry
    q: u32,     // the next face slot of the current neighbour, and its end
    end: u32,
    face: u32,  // the pair: its face and (node type, face type) index
    types: u32,
}

fn node_walk(i: u32, body: u32) -> NodeWalk {
    let row = nlist_row(i);
    return NodeWalk(body, row, min(nlist[row], P.nlist_cap), 0u, 0u, 0u, 0u, 0u);
}

fn next_node_pair(w: ptr<function, NodeWalk>) -> bool {
    var found = false;
    loop {
        if (*w).q < (*w).end {
            (*w).face = topo[P.off_first_faces + (*w).q];
            (*w).q += 1u;
            found = true;
            break;
        }
        if (*w).k >= (*w).count {
            break;
        }
        let j = nlist[(*w).row + 1u + (*w).k] & ~CONTACT_ONLY;
        (*w).k += 1u;
        let other = contact_body(j);
        if other == NO_BODY || other == (*w).body {
            (*w).k = (*w).count;
            break;
        }
        (*w).types = contact_types((*w).body, other);
        if topo[P.off_cany + (*w).types] != 0u {
            (*w).q = topo[P.off_first_start + j];
            (*w).end = topo[P.off_first_start + j + 1u];
        }
    }
    return found;
}

// The node–face pairs of particle i as a face corner, one per
// `next_corner_pair` (false when done): its faces (CSR, in face order) in
// batches of CORNER_BATCH — one walk of its row per batch, a mesh node's
// 5–6 faces in one — against each node of another body in its row with a
// contact rule, in row order, skipping the faces whose bounding sphere the
// node is outside (`corner_batch`); `role` is i's corner of the face.
struct CornerWalk {
    i: u32,
    body: u32,
    row: u32,
    count: u32,
    first: u32,        // the batch's first face slot, and the end of i's slots
    end: u32,
    batch: CornerBatch,
    k: u32,            // the next row entry
    q: u32,            // the next face of the batch for the current node
    node: u32,         // the pair: the node, its separation from i, the
    x: vec3<f32>,      // (node type, face type) index, the face and i's corner
    types: u32,
    face: u32,
    role: u32,
}

fn corner_walk(i: u32, body: u32) -> CornerWalk {
    var w: CornerWalk;
    w.i = i;
    w.body = body;
    w.row = nlist_row(i);
    w.count = min(nlist[w.row], P.nlist_cap);
    w.first = topo[P.off_corner_start + i];
    w.end = topo[P.off_corner_start + i + 1u];
    if w.first < w.end {
        w.batch = corner_batch(i, w.first, w.end);
    }
    w.q = CORNER_BATCH; // no node yet
    return w;
}

fn next_corner_pair(w: ptr<function, CornerWalk>) -> bool {
    var found = false;
    loop {
        while (*w).q < (*w).batch.count {
            let q = (*w).q;
            (*w).q += 1u;
            let off_centre = (*w).x - (*w).batch.centres[q];
            if dot(off_centre, off_centre) < (*w).batch.reach2[q] {
                (*w).face = (*w).batch.slots[q] / 4u;
                (*w).role = (*w).batch.slots[q] % 4u;
                found = true;
                break;
            }
        }
        if found || (*w).first >= (*w).end {
            break;
        }
        if (*w).k < (*w).count {
            let node = nlist[(*w).row + 1u + (*w).k] & ~CONTACT_ONLY;
            (*w).k += 1u;
            let other = contact_body(node);
            if other == NO_BODY || other == (*w).body {
                (*w).k = (*w).count; // the other bodies' nodes come first in the list
            } else {
                (*w).types = contact_types(other, (*w).body);
                if topo[P.off_cany + (*w).types] != 0u {
                    (*w).node = node;
                    (*w).x = separation((*w).i, node);
                    (*w).q = 0u;
                }
            }
            continue;
        }
        (*w).first += CORNER_BATCH;
        if (*w).first >= (*w).end {
            break;
        }
        (*w).batch = corner_batch((*w).i, (*w).first, (*w).end);
        (*w).k = 0u;
        (*w).q = CORNER_BATCH;
    }
    return found;
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
    var walk = node_walk(i, body);
    while next_node_pair(&walk) {
        let pair = contact_pair(i, walk.face);
        out.closest = min(out.closest, pair.d);
        let b = contact_radial(walk.types, pair.d);
        if b.de_dr != 0.0 {
            out.f -= b.de_dr * pair.n;
            out.e += b.energy;
        }
        if track && pair.d < P.contact_dhat {
            adhesion_track(i, walk.types, walk.face, pair.d);
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
        part = ContactNode(own.xyz, own.w, surf[contact_closest(i)].x);
    }
    var f = part.f;
    var e = part.e;
    var closest = part.closest;
    // As a corner: its faces against the other bodies' nodes (a face edge
    // longer than the search covers halts the run first).
    let corner_end = topo[P.off_corner_start + i + 1u];
    for (var q = topo[P.off_corner_start + i]; q < corner_end; q++) {
        let slot = topo[P.off_corner_faces + q];
        if slot % 4u == 0u && face_outgrew_search(slot / 4u) {
            atomicOr(&status[ST_HALTED], HALT_REACH);
        }
    }
    var walk = corner_walk(i, body);
    while next_corner_pair(&walk) {
        let pair = contact_pair(walk.node, walk.face);
        closest = min(closest, pair.d);
        let b = contact_radial(walk.types, pair.d);
        if b.de_dr != 0.0 {
            f += b.de_dr * pair.w[walk.role] * pair.n;
        }
        if P.n_arules > 0u {
            f += adhesion_corner(walk.node, walk.face, walk.role, walk.types, pair);
        }
    }
    let total = force[i] + vec4<f32>(f, e);
    force[i] = total;
    surf[contact_closest(i)] = vec4<f32>(closest, 0.0, 0.0, 0.0);
    // The step clamp: this particle's largest s, min-reduced through the bits.
    let s = contact_step_fraction(length(drift(i)), length(noise(i)), STEP_FRACTION * closest);
    atomicMin(&status[ST_FRACTION], bitcast<u32>(s));
}
