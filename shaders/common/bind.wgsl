// `bind` formation on the device (src/gpu/bind.rs has the buffer layout and
// the host side; the CPU's rule is src/kinetics_engine/formation.rs). Each
// step, after the breaks and rebinds of kinetics.wgsl (so bound counts are
// those after them) and before `advance`:
//   bind_count   per particle i: its candidates j > i — a rule's types, of
//                two bodies where the rule says `between bodies`, closer than
//                the capture radius, both under `max_bonds` bound bonds of
//                the rule's type, not already bound by one — that draw the
//                CPU's Philox number (i, j, step; seed ^ "bind") under
//                1 − exp(−k_on·Δt); per-block counts;
//   bind_scan    one workgroup: block bases, the step's candidate total;
//   bind_write   each particle's candidates at its base, sorted by j, so the
//                list is in ascending (i, j) order whatever the scheduling;
//   bind_accept  one invocation: the candidates in that order, each accepted
//                while both ends stay under `max_bonds` and the pair unbound
//                (as on the CPU): a pair with an unbound bond of the type
//                rebinds it, any other gets a new bond from the preallocated
//                pool (the next bond index, as the CPU appends) and a slot at
//                each end; its event follows the step's breaks.
// A step whose candidates could overflow the candidate list, the pool or an
// end's slots, or whose neighbour list overflowed, binds nothing here: `bind_accept` marks it and `bind_halt`
// (after `advance`, so the step counts) halts the run; the host decides that
// step's formation itself and rebuilds the backend, whose pool and slots
// then start empty (src/gpu/bind.rs).
//
// Bonds of a bind rule's type that existed when the backend was built are
// kinetic bonds in the particles' bond rows (terms from P.kin_first_term);
// bonds formed since live in the pool and are gathered through the slots.
//
// The header words of `kin` from KIN_SLOT_OF on, KIN_RULE_WORDS, BIND_RULES
// and FORMATION_SALT are the prelude's (src/gpu/prelude.rs).

fn bind_on() -> bool {
    return P.kin_bonds > 0u && kin_word(KIN_SLOT_WIDTH) > 0u;
}

// Particle i's slots: the word of the first, and how many (0: it takes no part).
fn slot_range(i: u32) -> vec2<u32> {
    let base = kin_word(kin_word(KIN_SLOT_OF) + i);
    if base == KIN_NONE {
        return vec2<u32>(0u);
    }
    return vec2<u32>(kin_word(KIN_SLOTS) + base, kin_word(KIN_SLOT_WIDTH));
}

// The other end of kinetic record k seen from particle i.
fn record_partner(k: u32, i: u32) -> u32 {
    let rec = kin_word(KIN_BONDS) + KIN_BOND_WORDS * k;
    let a = kin_word(rec);
    return select(a, kin_word(rec + 1u), a == i);
}

fn record_type(k: u32) -> u32 {
    return kin_word(kin_word(KIN_BONDS) + KIN_BOND_WORDS * k + 2u);
}

fn record_bound(k: u32) -> bool {
    return kin_word(kin_word(KIN_BOUND) + k) == 1u;
}

// Particle i's kinetic records, in bond order: those in its bond rows, then
// its slots. Each query below walks them.
struct BondsOfType {
    bound: u32,         // bound records of the type
    pair_bound: bool,   // one of them joins i and `partner`
    pair_unbound: u32,  // the first unbound record joining them (KIN_NONE: none)
}

fn bonds_of_type(i: u32, bond_type: u32, partner: u32) -> BondsOfType {
    var out = BondsOfType(0u, false, KIN_NONE);
    let end = topo[P.off_bond_offsets + i + 1u];
    for (var b = topo[P.off_bond_offsets + i]; b < end; b++) {
        let term = topo[P.off_bond_ends + 2u * b + 1u];
        if term < P.kin_first_term {
            continue;
        }
        bond_of_type_seen(&out, term - P.kin_first_term, topo[P.off_bond_ends + 2u * b], bond_type, partner);
    }
    let slots = slot_range(i);
    for (var s = 0u; s < slots.y; s++) {
        let k = kin_word(slots.x + s);
        if k == KIN_NONE {
            break;
        }
        bond_of_type_seen(&out, k, record_partner(k, i), bond_type, partner);
    }
    return out;
}

fn bond_of_type_seen(out: ptr<function, BondsOfType>, k: u32, other: u32, bond_type: u32, partner: u32) {
    if record_type(k) != bond_type {
        return;
    }
    if record_bound(k) {
        (*out).bound += 1u;
        (*out).pair_bound = (*out).pair_bound || other == partner;
    } else if other == partner && (*out).pair_unbound == KIN_NONE {
        (*out).pair_unbound = k;
    }
}

// Forces of the bound pool bonds at particle i (gathered; the rows hold the rest).
fn formed_bond_forces(i: u32) -> vec4<f32> {
    var f = vec3<f32>(0.0);
    var e = 0.0;
    if !bind_on() {
        return vec4<f32>(f, e);
    }
    let slots = slot_range(i);
    for (var s = 0u; s < slots.y; s++) {
        let k = kin_word(slots.x + s);
        if k == KIN_NONE {
            break;
        }
        if !record_bound(k) {
            continue;
        }
        let term = kin_word(kin_word(KIN_BONDS) + KIN_BOND_WORDS * k + 4u);
        let d = separation(i, record_partner(k, i));
        let r = length(d);
        let radial = radial_law(topo[P.off_term_kind + term], term_params(term), r);
        f += force_along(radial, d, r);
        e += 0.5 * radial.energy;
    }
    return vec4<f32>(f, e);
}

// What the candidate search reads of the rules and of particle i, loaded
// once per particle (the rules from `kin`, at most BIND_RULES of them).

struct BindSearch {
    rules: u32,
    type_a: vec4<u32>,
    type_b: vec4<u32>,
    between: vec4<u32>,
    capture: vec4<f32>,
    ti: u32,
    bi: u32,
}

fn bind_search_of(i: u32) -> BindSearch {
    var out: BindSearch;
    out.rules = min(kin_word(KIN_RULE_COUNT), BIND_RULES);
    for (var q = 0u; q < out.rules; q++) {
        let rec = kin_word(KIN_RULES) + KIN_RULE_WORDS * q;
        out.type_a[q] = kin_word(rec);
        out.type_b[q] = kin_word(rec + 1u);
        out.between[q] = kin_word(rec + 4u);
        out.capture[q] = kin_f32(rec + 5u);
    }
    out.ti = topo[i];
    out.bi = kin_word(kin_word(KIN_BODY) + i);
    return out;
}

// The rule that lets particles i and j (i < j) bind this step, if they are
// a candidate pair (KIN_NONE: not); `search` is i's.
fn bind_candidate(search: BindSearch, i: u32, j: u32) -> u32 {
    let ti = search.ti;
    let tj = topo[j];
    var k = KIN_NONE;
    for (var q = 0u; q < search.rules; q++) {
        let a = search.type_a[q];
        let b = search.type_b[q];
        if (a == ti && b == tj) || (a == tj && b == ti) {
            k = q;
            break;
        }
    }
    if k == KIN_NONE {
        return KIN_NONE;
    }
    if search.between[k] == 1u {
        let bj = kin_word(kin_word(KIN_BODY) + j);
        if search.bi == KIN_NONE || bj == KIN_NONE || search.bi == bj {
            return KIN_NONE;
        }
    }
    if length(separation(i, j)) >= search.capture[k] {
        return KIN_NONE;
    }
    let rec = kin_word(KIN_RULES) + KIN_RULE_WORDS * k;
    let bond_type = kin_word(rec + 2u);
    let max_bonds = kin_word(rec + 3u);
    let at_i = bonds_of_type(i, bond_type, j);
    if at_i.bound >= max_bonds || at_i.pair_bound || bonds_of_type(j, bond_type, i).bound >= max_bonds {
        return KIN_NONE;
    }
    let s = bitcast<f32>(atomicLoad(&status[ST_FRACTION]));
    let step = current_step();
    let x = philox4x32_10(vec4<u32>(i, j, step.x, step.y), vec2<u32>(P.seed_lo, P.seed_hi ^ FORMATION_SALT)).x;
    if !draws_below(x, one_minus_exp(kin_f32(rec + 6u) * s * kin_f32(KIN_DT))) {
        return KIN_NONE;
    }
    return k;
}

fn bind_row_count(i: u32) -> u32 {
    return min(nlist[nlist_row(i)], P.nlist_cap);
}

fn bind_row_entry(i: u32, m: u32) -> u32 {
    return nlist[nlist_row(i) + 1u + m] & ~CONTACT_ONLY;
}

@compute @workgroup_size(256)
fn bind_count(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = chunk_particle(wg, local);
    if !in_chunk(i) || halted() {
        return;
    }
    var count = 0u;
    if nlist[nlist_row(i)] > P.nlist_cap {
        atomicStore(&kin[KIN_DEFER], 1u); // the list overflowed: it may lack a partner
    }
    if kin_word(kin_word(KIN_SLOT_OF) + i) != KIN_NONE {
        let search = bind_search_of(i);
        let entries = bind_row_count(i);
        for (var m = 0u; m < entries; m++) {
            let j = bind_row_entry(i, m);
            if j > i && bind_candidate(search, i, j) != KIN_NONE {
                count += 1u;
            }
        }
    }
    atomicStore(&kin[kin_word(KIN_CAND_N) + i], count);
    if count > 0u {
        atomicAdd(&kin[kin_word(KIN_CAND_BLOCK) + i / WORKGROUP], count);
    }
}

// One workgroup: block bases (exclusive scan of the block counts, which are
// zeroed for the next step) and the step's total.
@compute @workgroup_size(256)
fn bind_scan(@builtin(local_invocation_index) local: u32) {
    let blocks = (P.n + WORKGROUP - 1u) / WORKGROUP;
    let counts = kin_word(KIN_CAND_BLOCK);
    let total = scan_block_counts(local, blocks, counts, counts + blocks, 0u, true, true);
    if local == 0u {
        atomicStore(&kin[KIN_CAND_TOTAL], select(0u, total, !halted()));
    }
}

@compute @workgroup_size(256)
fn bind_write(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = chunk_particle(wg, local);
    if !in_chunk(i) || halted() || kin_word(KIN_CAND_TOTAL) > kin_word(KIN_CAND_CAP) {
        return;
    }
    let counts = kin_word(KIN_CAND_N);
    if kin_word(counts + i) == 0u {
        return;
    }
    // Rank among this block's candidates: those of lower particles.
    let block = i / WORKGROUP;
    var at = kin_word(kin_word(KIN_CAND_BLOCK) + (P.n + WORKGROUP - 1u) / WORKGROUP + block);
    for (var q = block * WORKGROUP; q < i; q++) {
        at += kin_word(counts + q);
    }
    let first = kin_word(KIN_CAND) + 3u * at;
    var written = 0u;
    let search = bind_search_of(i);
    let entries = bind_row_count(i);
    for (var m = 0u; m < entries; m++) {
        let j = bind_row_entry(i, m);
        if j <= i {
            continue;
        }
        let k = bind_candidate(search, i, j);
        if k == KIN_NONE {
            continue;
        }
        // Insertion by j.
        var w = first + 3u * written;
        while w > first && kin_word(w - 2u) > j {
            atomicStore(&kin[w], kin_word(w - 3u));
            atomicStore(&kin[w + 1u], kin_word(w - 2u));
            atomicStore(&kin[w + 2u], kin_word(w - 1u));
            w -= 3u;
        }
        atomicStore(&kin[w], i);
        atomicStore(&kin[w + 1u], j);
        atomicStore(&kin[w + 2u], k);
        written += 1u;
    }
}

fn free_slots(i: u32) -> u32 {
    let slots = slot_range(i);
    var used = 0u;
    while used < slots.y && kin_word(slots.x + used) != KIN_NONE {
        used += 1u;
    }
    return slots.y - used;
}

// Whether every candidate can be taken without running out of pool records
// or of either end's slots (a particle gains at most Σ max_bonds new bonds
// in a step).
fn bind_room(total: u32) -> bool {
    if total > kin_word(KIN_CAND_CAP) || kin_word(KIN_POOL_END) - kin_word(KIN_POOL_NEXT) < total {
        return false;
    }
    let gain = kin_word(KIN_MAX_GAIN);
    for (var c = 0u; c < total; c++) {
        let at = kin_word(KIN_CAND) + 3u * c;
        if free_slots(kin_word(at)) < gain || free_slots(kin_word(at + 1u)) < gain {
            return false;
        }
    }
    return true;
}

fn take_slot(i: u32, k: u32) {
    let slots = slot_range(i);
    var s = 0u;
    while kin_word(slots.x + s) != KIN_NONE {
        s += 1u;
    }
    atomicStore(&kin[slots.x + s], k);
}

fn bind_event(k: u32, kind: u32, length_: f32) {
    let slot = atomicAdd(&kin[KIN_CURSOR], 1u);
    let e = kin_word(KIN_EVENTS) + KIN_EVENT_WORDS * slot;
    let step = current_step();
    atomicStore(&kin[e], step.x);
    atomicStore(&kin[e + 1u], step.y);
    atomicStore(&kin[e + 2u], kin_word(kin_word(KIN_BONDS) + KIN_BOND_WORDS * k + 3u));
    atomicStore(&kin[e + 3u], kind);
    atomicStore(&kin[e + 4u], 0u);
    atomicStore(&kin[e + 5u], bitcast<u32>(length_));
    atomicStore(&kin[e + 6u], 0u);
    atomicStore(&kin[e + 7u], 0u);
}

@compute @workgroup_size(1)
fn bind_accept() {
    if halted() {
        return;
    }
    let total = kin_word(KIN_CAND_TOTAL);
    if kin_word(KIN_DEFER) != 0u {
        return;
    }
    if total == 0u {
        return;
    }
    if !bind_room(total) {
        atomicStore(&kin[KIN_DEFER], 1u);
        return;
    }
    for (var c = 0u; c < total; c++) {
        let at = kin_word(KIN_CAND) + 3u * c;
        let i = kin_word(at);
        let j = kin_word(at + 1u);
        let rule = kin_word(KIN_RULES) + KIN_RULE_WORDS * kin_word(at + 2u);
        let bond_type = kin_word(rule + 2u);
        let max_bonds = kin_word(rule + 3u);
        let at_i = bonds_of_type(i, bond_type, j);
        if at_i.bound >= max_bonds || at_i.pair_bound || bonds_of_type(j, bond_type, i).bound >= max_bonds {
            continue;
        }
        var k = at_i.pair_unbound;
        var kind = EVENT_REBIND;
        if k == KIN_NONE {
            // A new bond: the next pool record and bond index.
            k = kin_word(KIN_POOL_NEXT);
            atomicStore(&kin[KIN_POOL_NEXT], k + 1u);
            let bond = kin_word(KIN_NEXT_BOND);
            atomicStore(&kin[KIN_NEXT_BOND], bond + 1u);
            let rec = kin_word(KIN_BONDS) + KIN_BOND_WORDS * k;
            atomicStore(&kin[rec], i);
            atomicStore(&kin[rec + 1u], j);
            atomicStore(&kin[rec + 2u], bond_type);
            atomicStore(&kin[rec + 3u], bond);
            atomicStore(&kin[rec + 4u], bond_type); // the type's own term (terms start with the bond types)
            atomicStore(&kin[rec + 5u], kin_word(rule + 7u));
            take_slot(i, k);
            take_slot(j, k);
            kind = EVENT_FORM;
        }
        atomicStore(&kin[kin_word(KIN_BOUND) + k], 1u);
        let age = kin_word(KIN_AGE) + 2u * k;
        atomicStore(&kin[age], 0u);
        atomicStore(&kin[age + 1u], 0u);
        bind_event(k, kind, length(separation(i, j)));
    }
}

// After `advance`: a step whose formation was left to the host halts the run.
@compute @workgroup_size(1)
fn bind_halt() {
    if kin_word(KIN_DEFER) != 0u {
        atomicOr(&status[ST_HALTED], HALT_FORMATION);
    }
}
