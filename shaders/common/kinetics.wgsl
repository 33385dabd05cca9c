// Bond kinetics on the device (src/gpu/kinetics.rs has the buffer layout and
// the host side). Each step, after the force pass:
//   kin_measure  each kinetic bond's tension dE/dr and length at x_s (f32);
// after `commit` (so a refused step changes nothing):
//   kin_decide   each bond's break or rebind with the CPU's Philox key
//                (seed, s, bond, stream 2), its bound flag and its f64 age
//                (advanced by the step's length f64(s)·dt — s the contact
//                clamp's fraction, 1 without — with an exact integer f64
//                product and addition, so ages are the CPU's bits);
//                per-block event counts;
//   kin_scan     one workgroup: exclusive scan of the block counts into the
//                event buffer's cursor, coarse-step warnings;
//   kin_emit     each event written at its block base + its rank in the block,
//                so events are in bond order (no float atomics, no order
//                dependence).
// Before every step `kin_room` halts the run (HALT_EVENTS) when the event
// buffer could not take one more step's events; the host drains it and goes on.
//
// The header words of `kin` (KIN_BONDS …), its record sizes, the event kinds,
// the Philox streams and COARSE_RATE_DT are the prelude's (src/gpu/prelude.rs).
// Each rule is decided by its device form (FORM_RATE, FORM_BEYOND,
// FORM_ON_RATE): the generated `rule_form`, `unbind_law`, `threshold_law` and
// `rebind_law` dispatch on the rule's code to its evaluator beside the rule
// (src/kinetics/NAME.wgsl, src/gpu/shader.rs).

// A threshold rule's verdict at a bond: beyond its threshold, and its break
// rate there (0: at once).
struct Beyond {
    over: bool,
    rate: f32,
}

fn kin_word(k: u32) -> u32 {
    return atomicLoad(&kin[k]);
}

fn kin_f32(k: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&kin[k]));
}

// 1 for a bound bond, 0 for an unbound one: scales a term's force in the
// force pass (every term but a kinetic bond's own is 1).
fn bond_on(term: u32) -> f32 {
    if P.kin_bonds == 0u || term < P.kin_first_term {
        return 1.0;
    }
    return f32(kin_word(kin_word(KIN_BOUND) + term - P.kin_first_term));
}

// Whether exclusion entry `e` (index into the `topo` exclusion list) holds:
// an entry made by a kinetic bond holds only while that bond is bound.
fn exclusion_on(e: u32) -> bool {
    if P.kin_bonds == 0u {
        return true;
    }
    let tag = kin_word(kin_word(KIN_EXCL) + e);
    return tag == KIN_NONE || kin_word(kin_word(KIN_BOUND) + tag) == 1u;
}

@compute @workgroup_size(1)
fn kin_room() {
    // A step's events: at most one per kinetic bond, and its bindings (bind.wgsl).
    if kin_word(KIN_CURSOR) + P.kin_bonds + kin_word(KIN_CAND_CAP) > P.kin_capacity {
        atomicOr(&status[ST_HALTED], HALT_EVENTS);
    }
}

@compute @workgroup_size(256)
fn kin_measure(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = linear_index(wg, local);
    if k >= P.kin_bonds || halted() {
        return;
    }
    let rec = kin_word(KIN_BONDS) + KIN_BOND_WORDS * k;
    if kin_word(rec) == KIN_NONE {
        return; // a pool record not yet taken (bind.wgsl)
    }
    let d = separation(kin_word(rec), kin_word(rec + 1u));
    let r = length(d);
    let term = kin_word(rec + 4u);
    var tension = 0.0;
    if kin_word(kin_word(KIN_BOUND) + k) == 1u {
        tension = fparams[P.off_term_scale + term] * radial_law(topo[P.off_term_kind + term], term_params(term), r).de_dr;
    }
    let m = kin_word(KIN_MEASURE) + 3u * k;
    atomicStore(&kin[m], bitcast<u32>(tension));
    atomicStore(&kin[m + 1u], bitcast<u32>(r));
}

// 1 − exp(−a) without cancellation for small a (Taylor to a⁶ below 0.1:
// relative error < 1e-9 there).
fn one_minus_exp(a: f32) -> f32 {
    if a < 0.1 {
        return a * (1.0 - a * (0.5 - a * (1.0 / 6.0 - a * (1.0 / 24.0 - a * (1.0 / 120.0 - a / 720.0)))));
    }
    return 1.0 - exp(-a);
}

// The CPU's test u < p with u = (x + ½)/2³² (f32: p's rounding decides only
// when u lies within ~1e-7·p of p).
fn draws_below(x: u32, p: f32) -> bool {
    return p >= 1.0 || f32(x) + 0.5 < p * 4294967296.0;
}

// The eight parameters of the rule record at word p (f32 bits).
fn kin_rule_params(p: u32) -> array<f32, 8> {
    return array<f32, 8>(kin_f32(p), kin_f32(p + 1u), kin_f32(p + 2u), kin_f32(p + 3u), kin_f32(p + 4u), kin_f32(p + 5u), kin_f32(p + 6u), kin_f32(p + 7u));
}

// f64 addition a + b of two finite non-negative numbers given as (high, low)
// words, rounded to nearest even as IEEE 754 does, in integer arithmetic
// (WGSL has no f64): the ages are the CPU's bits.
fn u64_shr(m: vec2<u32>, n: u32) -> vec2<u32> {
    if n == 0u {
        return m;
    }
    if n >= 64u {
        return vec2<u32>(0u);
    }
    if n >= 32u {
        return vec2<u32>(0u, m.x >> (n - 32u));
    }
    return vec2<u32>(m.x >> n, (m.y >> n) | (m.x << (32u - n)));
}

// Shifted right by n with the bits shifted out ORed into bit 0 (sticky).
fn u64_shr_sticky(m: vec2<u32>, n: u32) -> vec2<u32> {
    var lost = false;
    if n >= 64u {
        lost = (m.x | m.y) != 0u;
    } else if n >= 32u {
        lost = m.y != 0u || (m.x & ((1u << (n - 32u)) - 1u)) != 0u;
    } else if n > 0u {
        lost = (m.y & ((1u << n) - 1u)) != 0u;
    }
    var r = u64_shr(m, n);
    if lost {
        r.y |= 1u;
    }
    return r;
}

fn u64_add(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.y + b.y;
    return vec2<u32>(a.x + b.x + select(0u, 1u, lo < a.y), lo);
}

fn f64_add(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    if (a.x | a.y) == 0u {
        return b;
    }
    if (b.x | b.y) == 0u {
        return a;
    }
    var ea = a.x >> 20u;
    var eb = b.x >> 20u;
    // Mantissas with the implicit bit, three guard bits below.
    var ma = vec2<u32>((a.x & 0xFFFFFu) | select(0u, 0x100000u, ea != 0u), a.y);
    var mb = vec2<u32>((b.x & 0xFFFFFu) | select(0u, 0x100000u, eb != 0u), b.y);
    ea = max(ea, 1u);
    eb = max(eb, 1u);
    if eb > ea {
        let m = ma;
        let e = ea;
        ma = mb;
        ea = eb;
        mb = m;
        eb = e;
    }
    ma = vec2<u32>((ma.x << 3u) | (ma.y >> 29u), ma.y << 3u);
    mb = vec2<u32>((mb.x << 3u) | (mb.y >> 29u), mb.y << 3u);
    var s = u64_add(ma, u64_shr_sticky(mb, ea - eb));
    var e = ea;
    if (s.x >> 24u) != 0u {
        s = u64_shr_sticky(s, 1u);
        e += 1u;
    }
    let guard = s.y & 7u;
    s = u64_shr(s, 3u);
    if guard > 4u || (guard == 4u && (s.y & 1u) == 1u) {
        s = u64_add(s, vec2<u32>(0u, 1u));
        if (s.x >> 21u) != 0u {
            s = u64_shr(s, 1u);
            e += 1u;
        }
    }
    if (s.x & 0x100000u) == 0u {
        e = 0u; // both subnormal and the sum still is
    }
    return vec2<u32>((e << 20u) | (s.x & 0xFFFFFu), s.y);
}

// The f64 product f64(s)·x of a positive normal f64 x (high, low words) and
// a normal f32 s in (0, 1], rounded to nearest even as IEEE 754 does, in
// integer arithmetic: the CPU's step length `fraction * dt` (the fraction
// widened from the device's f32 s), so ages advance by the CPU's bits.
// The product's exponent stays normal for any dt ≥ 1e-270; s = 0 (a node
// on a face: the clamp stops the step) gives 0.
fn f64_scale(x: vec2<u32>, s: f32) -> vec2<u32> {
    if s == 1.0 {
        return x;
    }
    if s <= 0.0 {
        return vec2<u32>(0u);
    }
    let bits = bitcast<u32>(s);
    let ms = (bits & 0x7FFFFFu) | 0x800000u; // 24 bits
    let mh = (x.x & 0xFFFFFu) | 0x100000u;   // the high 21 of 53 bits
    // ms · (mh·2³² + x.y) in three words w2:w1:w0, in [2⁷⁵, 2⁷⁷).
    let low = mulhilo(ms, x.y); // philox.wgsl
    let high = mulhilo(ms, mh);
    let w0 = low.y;
    let w1 = low.x + high.y;
    let w2 = high.x + select(0u, 1u, w1 < low.x);
    // Keep 53 bits: shift out 23 or 24, rounding to nearest even.
    let sh = select(23u, 24u, (w2 >> 12u) != 0u);
    var m = vec2<u32>((w1 >> sh) | (w2 << (32u - sh)), (w0 >> sh) | (w1 << (32u - sh)));
    let half = 1u << (sh - 1u);
    let rest = w0 & ((half << 1u) - 1u);
    var e = sh + ((bits >> 23u) & 0xFFu) + ((x.x >> 20u) & 0x7FFu) - 150u;
    if rest > half || (rest == half && (m.y & 1u) == 1u) {
        m = u64_add(m, vec2<u32>(0u, 1u));
        if (m.x >> 21u) != 0u {
            m = u64_shr(m, 1u);
            e += 1u;
        }
    }
    return vec2<u32>((e << 20u) | (m.x & 0xFFFFFu), m.y);
}

var<workgroup> kin_block_events: atomic<u32>;

@compute @workgroup_size(256)
fn kin_decide(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if local == 0u {
        atomicStore(&kin_block_events, 0u);
    }
    workgroupBarrier();
    let k = linear_index(wg, local);
    var kind = 0u;
    if k < P.kin_bonds && !halted() {
        kind = kin_decide_bond(k);
        atomicStore(&kin[kin_word(KIN_FLAG) + k], kind);
        if kind != 0u {
            atomicAdd(&kin_block_events, 1u);
        }
    }
    workgroupBarrier();
    if local == 0u && !halted() {
        atomicStore(&kin[kin_word(KIN_BLOCK) + linear_index(wg, 0u) / WORKGROUP], atomicLoad(&kin_block_events));
    }
}

// One bond's decision (as `decide` in src/kinetics_engine/engine.rs); updates
// its bound flag and age, returns its event kind (0: none).
fn kin_decide_bond(k: u32) -> u32 {
    let rec = kin_word(KIN_BONDS) + KIN_BOND_WORDS * k;
    if kin_word(rec) == KIN_NONE {
        return 0u; // a pool record not yet taken (bind.wgsl)
    }
    let bond = kin_word(rec + 3u);
    let trec = kin_word(KIN_TYPE) + KIN_TYPE_WORDS * kin_word(rec + 2u);
    let rules = kin_word(trec);
    if rules == 0u {
        return 0u;
    }
    let m = kin_word(KIN_MEASURE) + 3u * k;
    let force = kin_f32(m);
    let len = kin_f32(m + 1u);
    // The step took s·dt (s < 1 where the contact step clamp shortened it):
    // rates act over it and ages advance by it, as on the CPU.
    let s = bitcast<f32>(atomicLoad(&status[ST_FRACTION]));
    let dt = s * kin_f32(KIN_DT);
    let kt = kin_f32(KIN_KT);
    let seed = vec2<u32>(P.seed_lo, P.seed_hi);
    let x = philox4x32_10(vec4<u32>(bond, STREAM_KINETICS, current_step()), seed).x;
    let bound_at = kin_word(KIN_BOUND) + k;
    let age_at = kin_word(KIN_AGE) + 2u * k;
    if kin_word(bound_at) == 0u {
        for (var r = 0u; r < rules; r++) {
            let p = trec + KIN_TYPE_RULES + KIN_RULE_STRIDE * r;
            let code = kin_word(p);
            if rule_form(code) != FORM_ON_RATE {
                continue;
            }
            let on = rebind_law(code, kin_rule_params(p + 1u));
            if len < on.y && draws_below(x, one_minus_exp(on.x * dt)) {
                atomicStore(&kin[bound_at], 1u);
                atomicStore(&kin[age_at], 0u);
                atomicStore(&kin[age_at + 1u], 0u);
                return EVENT_REBIND;
            }
        }
        return 0u;
    }
    let rest = kin_f32(rec + 5u);
    let strain = select(0.0, (len - rest) / rest, rest > 0.0);
    var rate = 0.0;
    var immediate = false;
    for (var r = 0u; r < rules; r++) {
        let p = trec + KIN_TYPE_RULES + KIN_RULE_STRIDE * r;
        let code = kin_word(p);
        let form = rule_form(code);
        if form == FORM_BEYOND {
            let u = (f32(philox4x32_10(vec4<u32>(bond, STREAM_QUENCHED, KIN_NONE, KIN_NONE), seed).x) + 0.5) * 2.3283064365386963e-10;
            let beyond = threshold_law(code, kin_rule_params(p + 1u), force, strain, u);
            if beyond.over {
                if beyond.rate > 0.0 {
                    rate += beyond.rate;
                } else {
                    immediate = true;
                }
            }
        } else if form == FORM_RATE {
            rate += unbind_law(code, kin_rule_params(p + 1u), force, kt);
        }
    }
    let rate_dt = rate * dt;
    atomicStore(&kin[m + 2u], bitcast<u32>(rate_dt));
    if rate_dt > COARSE_RATE_DT && kin_word(trec + 1u) == 0u {
        atomicMin(&kin[trec + 2u], k);
    }
    let step_length = f64_scale(vec2<u32>(kin_word(KIN_DT_HI), kin_word(KIN_DT_LO)), s);
    let age = f64_add(vec2<u32>(kin_word(age_at), kin_word(age_at + 1u)), step_length);
    atomicStore(&kin[age_at], age.x);
    atomicStore(&kin[age_at + 1u], age.y);
    if immediate || (rate > 0.0 && draws_below(x, one_minus_exp(rate_dt))) {
        atomicStore(&kin[bound_at], 0u);
        return EVENT_BREAK;
    }
    return 0u;
}

var<workgroup> block_partial: array<u32, 256>;

// One workgroup (all of it calls this): the bases of `blocks` block counts
// (words `counts`…) as `start` + their exclusive scan, written to words
// `bases`… when `go`; with `clear`, each count is zeroed once read. Returns
// the counts' total. Used by kin_scan and bind_scan (bind.wgsl).
fn scan_block_counts(local: u32, blocks: u32, counts: u32, bases: u32, start: u32, go: bool, clear: bool) -> u32 {
    let per = (blocks + WORKGROUP - 1u) / WORKGROUP;
    let first = min(local * per, blocks);
    let end = min(first + per, blocks);
    var sum = 0u;
    for (var b = first; b < end; b++) {
        sum += kin_word(counts + b);
    }
    block_partial[local] = sum;
    workgroupBarrier();
    // Inclusive Hillis–Steele scan of the 256 partial sums.
    for (var step = 1u; step < WORKGROUP; step *= 2u) {
        var v = block_partial[local];
        if local >= step {
            v += block_partial[local - step];
        }
        workgroupBarrier();
        block_partial[local] = v;
        workgroupBarrier();
    }
    var base = start + block_partial[local] - sum;
    for (var b = first; b < end && go; b++) {
        let count = kin_word(counts + b);
        atomicStore(&kin[bases + b], base);
        if clear {
            atomicStore(&kin[counts + b], 0u);
        }
        base += count;
    }
    let total = block_partial[WORKGROUP - 1u];
    workgroupBarrier();
    return total;
}

// One workgroup: block bases = cursor + exclusive scan of the block counts.
@compute @workgroup_size(256)
fn kin_scan(@builtin(local_invocation_index) local: u32) {
    let blocks = (P.kin_bonds + WORKGROUP - 1u) / WORKGROUP;
    let counts = kin_word(KIN_BLOCK);
    // A halted step decided nothing (the halt was set before this step).
    let go = !halted();
    let cursor = kin_word(KIN_CURSOR);
    let total = scan_block_counts(local, blocks, counts, counts + blocks, cursor, go, false);
    if !go {
        return;
    }
    if local == 0u {
        atomicStore(&kin[KIN_CURSOR], cursor + total);
        if total > 0u && !bind_on() {
            // Breaks and rebinds change the pair exclusions. With `bind` on
            // the device the list keeps bonded pairs (neighbor.wgsl): it does
            // not depend on the bonds, and is not rebuilt for them.
            atomicStore(&status[ST_FORCE_REBUILD], 1u);
        }
    }
    // Coarse-step warnings: the lowest bond of each type over k·dt = 0.1, once.
    for (var t = local; t < P.kin_types; t += WORKGROUP) {
        let trec = kin_word(KIN_TYPE) + KIN_TYPE_WORDS * t;
        let k = kin_word(trec + 2u);
        if kin_word(trec + 1u) == 0u && k != KIN_NONE {
            let step = current_step();
            atomicStore(&kin[trec + 1u], 1u);
            atomicStore(&kin[trec + 3u], step.x);
            atomicStore(&kin[trec + 4u], step.y);
            atomicStore(&kin[trec + 5u], kin_word(kin_word(KIN_MEASURE) + 3u * k + 2u));
        }
    }
}

@compute @workgroup_size(256)
fn kin_emit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = linear_index(wg, local);
    if k >= P.kin_bonds || halted() {
        return;
    }
    let flags = kin_word(KIN_FLAG);
    let kind = kin_word(flags + k);
    if kind == 0u {
        return;
    }
    // Rank among this block's events: those of lower bonds.
    let block = k / WORKGROUP;
    var rank = 0u;
    for (var q = block * WORKGROUP; q < k; q++) {
        rank += select(0u, 1u, kin_word(flags + q) != 0u);
    }
    let blocks = (P.kin_bonds + WORKGROUP - 1u) / WORKGROUP;
    let slot = kin_word(kin_word(KIN_BLOCK) + blocks + block) + rank;
    let e = kin_word(KIN_EVENTS) + KIN_EVENT_WORDS * slot;
    let rec = kin_word(KIN_BONDS) + KIN_BOND_WORDS * k;
    let m = kin_word(KIN_MEASURE) + 3u * k;
    let age_at = kin_word(KIN_AGE) + 2u * k;
    let step = current_step();
    atomicStore(&kin[e], step.x);
    atomicStore(&kin[e + 1u], step.y);
    atomicStore(&kin[e + 2u], kin_word(rec + 3u));
    atomicStore(&kin[e + 3u], kind);
    atomicStore(&kin[e + 4u], kin_word(m));
    atomicStore(&kin[e + 5u], kin_word(m + 1u));
    atomicStore(&kin[e + 6u], kin_word(age_at));
    atomicStore(&kin[e + 7u], kin_word(age_at + 1u));
}
