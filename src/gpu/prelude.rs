//! The constants the host and the kernels share, written once in Rust and
//! generated into the program's prelude (src/gpu/shader.rs), so no WGSL file
//! restates a number the host also relies on and no test has to hold two
//! copies equal.
//!
//! This file is the one home of the GPU buffers' shared layout, as a C
//! header is between a CUDA host and its kernels: one group per module that
//! writes or reads the buffer (`prelude::kinetics` for src/gpu/kinetics.rs and
//! kinetics.wgsl, …), each declared with [`shared_constants!`], which defines
//! each word index, halt bit or record size as a Rust `const` and lists it in
//! the group's `WGSL` table; a constant defined below the GPU (a physics
//! constant: the contact step fraction, FIRE's parameters, the kinetics'
//! Philox streams) is listed by reference with [`WgslConst::f32`] or
//! [`WgslConst::u32`]. The composer writes one `const NAME: u32 = VALUE;` (or
//! `f32`) per entry of every table in [`TABLES`] before the common files.
//! Constants only the kernels use (indices into their own scratch) stay in
//! their WGSL files.
//!
//! The groups live here rather than in their modules because the composer
//! needs all of them and most modules need the composer: kept beside their
//! modules, they would tie the whole folder into one import circle. This file
//! imports nothing of src/gpu/.

/// A constant's value in the program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WgslValue {
    U32(u32),
    /// An f32 written from its f64 definition (WGSL rounds the literal to f32
    /// as the host's `as f32` does).
    F32(f64),
}

/// One constant of the prelude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WgslConst {
    pub name: &'static str,
    pub value: WgslValue,
}

impl WgslConst {
    pub const fn u32(name: &'static str, value: u32) -> Self {
        Self { name, value: WgslValue::U32(value) }
    }

    pub const fn f32(name: &'static str, value: f64) -> Self {
        Self { name, value: WgslValue::F32(value) }
    }

    /// The WGSL declaration: `const NAME: u32 = 7u;`.
    pub fn declaration(&self) -> String {
        match self.value {
            WgslValue::U32(v) if v >= 0x1000_0000 => format!("const {}: u32 = 0x{v:08x}u;\n", self.name),
            WgslValue::U32(v) => format!("const {}: u32 = {v}u;\n", self.name),
            WgslValue::F32(v) => format!("const {}: f32 = {v:?};\n", self.name),
        }
    }
}

/// Defines integer constants (`u32`, or `usize` where the host indexes with
/// them; `u32` in WGSL) and the group's `pub(super) static WGSL: &[WgslConst]`
/// table of them (plus any further entries given after `;`), so that each
/// is written once, in Rust, and generated into the program's prelude.
///
/// ```ignore
/// shared_constants! {
///     /// Header word: offset of the bond records.
///     pub(in crate::gpu) const KIN_BONDS: usize = 0;
///     ;
///     WgslConst::f32("COARSE_RATE_DT", COARSE_RATE_DT),
/// }
/// ```
macro_rules! shared_constants {
    ($($(#[$doc:meta])* $vis:vis const $name:ident: $ty:ty = $value:expr;)* $(; $($extra:expr),* $(,)?)?) => {
        $($(#[$doc])* $vis const $name: $ty = $value;)*
        /// This group's constants in the program's prelude.
        pub(super) static WGSL: &[$crate::gpu::prelude::WgslConst] = &[
            $($crate::gpu::prelude::WgslConst::u32(stringify!($name), $name as u32),)*
            $($($extra,)*)?
        ];
    };
}

/// Shared by src/gpu/pack.rs and its kernels.
pub(super) mod pack {
    shared_constants! {
        /// Parameter slots per term on the GPU.
        pub const PARAM_SLOTS: usize = 8;
    }
}

/// Shared by src/gpu/backend/ and its kernels.
pub(super) mod status {
    shared_constants! {
        /// Words of `status`, read back by the host at every synchronisation.
        pub(in crate::gpu) const STATUS_WORDS: usize = 11;
        /// `status` word: the halt bits (HALT_*); kernels stop when any is set.
        pub(in crate::gpu) const ST_HALTED: usize = 0;
        /// `status` word: the largest neighbour count met (when it overflowed).
        pub(in crate::gpu) const ST_OVERFLOW_NEED: usize = 1;
        /// `status` word: bits of the largest squared displacement since the last build.
        pub(in crate::gpu) const ST_MAX_DISP2: usize = 2;
        /// `status` word: neighbour-list builds so far.
        pub(in crate::gpu) const ST_BUILDS: usize = 3;
        /// `status` word: steps completed in this call.
        pub(in crate::gpu) const ST_STEPS_DONE: usize = 4;
        /// `status` word: the lowest particle index whose step was refused (NO_PARTICLE: none).
        pub(in crate::gpu) const ST_BLOWUP_PARTICLE: usize = 5;
        /// `status` word: host request to rebuild the list before the next step.
        pub(in crate::gpu) const ST_FORCE_REBUILD: usize = 6;
        /// `status` word: the lowest packed body wider than half the periodic box.
        pub(in crate::gpu) const ST_SPAN_BODY: usize = 7;
        /// `status` word: this step's fraction s of dt (f32 bits; the contact step clamp, src/gpu/contact.rs; 1.0 without).
        pub(in crate::gpu) const ST_FRACTION: usize = 8;
        /// `status` word: the fractions of dt of this call's steps, summed (f32 bits; `sim_time` in integrate.wgsl).
        pub(in crate::gpu) const ST_ELAPSED: usize = 9;
        /// `status` word: 1 while the list is checked after `commit` (bind.wgsl): an overflow there defers, not halts.
        pub(in crate::gpu) const ST_LIST_AFTER_STEP: usize = 10;
        /// ST_BLOWUP_PARTICLE (and ST_SPAN_BODY) while no step was refused.
        pub(in crate::gpu) const NO_PARTICLE: u32 = u32::MAX;
        /// Halt bit: the neighbour list overflowed.
        pub(in crate::gpu) const HALT_OVERFLOW: u32 = 1;
        /// Halt bit: a step was refused (non-finite or beyond max_displacement).
        pub(in crate::gpu) const HALT_BLOWUP: u32 = 2;
        /// Halt bit: a body spans more than half the periodic box (src/gpu/surface.rs).
        pub(in crate::gpu) const HALT_SPAN: u32 = 4;
        /// Halt bit: a face edge outgrew the contact search (src/gpu/contact.rs).
        pub(in crate::gpu) const HALT_REACH: u32 = 8;
        /// Halt bit: the event buffer of the device kinetics is full (src/gpu/kinetics.rs).
        pub(in crate::gpu) const HALT_EVENTS: u32 = 16;
        /// Halt bit: the implicit step's solve did not converge (src/gpu/implicit.rs).
        pub(in crate::gpu) const HALT_SOLVE: u32 = 32;
        /// Halt bit: a step's `bind` formation was left to the host (src/gpu/bind.rs).
        pub(in crate::gpu) const HALT_FORMATION: u32 = 64;
        /// Halt bit: a constraint projection did not converge (src/gpu/shake.rs).
        pub(in crate::gpu) const HALT_CONSTRAINT: u32 = 128;
        /// Halt bit: FIRE converged, max |F| < ftol (src/gpu/fire.rs).
        pub(in crate::gpu) const HALT_CONVERGED: u32 = 256;
    }
}

/// Shared by src/gpu/context.rs and its kernels.
pub(super) mod context {
    shared_constants! {
        /// Invocations per workgroup of every kernel.
        pub const WORKGROUP: u32 = 256;
    }
}

/// Shared by src/gpu/contact.rs and its kernels.
pub(super) mod contact {
    use super::WgslConst;

    shared_constants! {
        /// Steps whose fractions the device keeps between two host syncs (the ring in `surf`).
        pub const FRACTION_SLOTS: u32 = 1024;
        /// Words per contact rule: registry index, then 8 parameters (f32 bits).
        pub(in crate::gpu) const CONTACT_RULE_WORDS: usize = 9;
        /// Marks a neighbour-list entry kept only for the contact search.
        pub const CONTACT_ONLY: u32 = 1 << 31;
        /// A particle's body where it is in none.
        pub(in crate::gpu) const NO_BODY: u32 = u32::MAX;
        ;
        // The step clamp: a particle moves at most this fraction of its closest contact distance (the CPU's).
        WgslConst::f32("STEP_FRACTION", crate::backend::CONTACT_STEP_FRACTION),
    }
}

/// Shared by src/gpu/fire.rs and its kernels.
pub(super) mod fire {
    use super::WgslConst;
    use crate::integrate::fire::{ALPHA0, F_ALPHA, F_DEC, F_INC, N_MIN};

    shared_constants! {
        /// `fire` entry: (Δt, α, positive steps (bits), iterations (bits)).
        pub(in crate::gpu) const FIRE_STATE: usize = 0;
        /// `fire` entry: (1 − α or 0, α|v|/|F| or 0, Δt₀, Δt_max).
        pub(in crate::gpu) const FIRE_MIXING: usize = 1;
        /// `fire` entry: (ftol, dmax, max |F| of the last evaluation, blocks (bits)).
        pub(in crate::gpu) const FIRE_LIMITS: usize = 2;
        /// `fire` entry: (moves the contact step clamp shortened (bits), 0, 0, 0).
        pub(in crate::gpu) const FIRE_CLAMPED: usize = 3;
        /// `fire` entries from here: one per workgroup of `fire_partials`, (P, Σ|v|², Σ|F|², max |F|).
        pub(in crate::gpu) const FIRE_PARTIALS: usize = 4;
        ;
        // FIRE's parameters are the CPU's (src/integrate/fire.rs).
        WgslConst::u32("FIRE_N_MIN", N_MIN),
        WgslConst::f32("FIRE_F_INC", F_INC),
        WgslConst::f32("FIRE_F_DEC", F_DEC),
        WgslConst::f32("FIRE_ALPHA0", ALPHA0),
        WgslConst::f32("FIRE_F_ALPHA", F_ALPHA),
    }
}

/// Shared by src/gpu/implicit.rs and its kernels.
pub(super) mod implicit {
    shared_constants! {
        /// `imp_topo` header word: the number of angles.
        pub(in crate::gpu) const IMP_ANGLES: usize = 0;
        /// `imp_topo` header word: offset of the angle records (i, j, k, term).
        pub(in crate::gpu) const IMP_OFF_ANGLES: usize = 1;
        /// `imp_topo` header word: offset of each particle's start of its angle slots (n + 1).
        pub(in crate::gpu) const IMP_OFF_SLOT_START: usize = 2;
        /// `imp_topo` header word: offset of the angle slots (angle, role).
        pub(in crate::gpu) const IMP_OFF_SLOTS: usize = 3;
        /// `imp_topo` header word: the CG iteration cap.
        pub(in crate::gpu) const IMP_MAX_ITER: usize = 4;
        /// `imp_topo` header word: the relative residual |r|/|b| (f32 bits).
        pub(in crate::gpu) const IMP_TOLERANCE: usize = 5;
        /// `imp_topo` header word: offset of γ/dt per type (f32 bits; 0 for a fixed type).
        pub(in crate::gpu) const IMP_OFF_DRAG: usize = 6;
        /// `imp_topo` header word: offset of √(2kT·γ/dt) per type (f32 bits).
        pub(in crate::gpu) const IMP_OFF_KICK: usize = 7;
        /// `imp_topo` header word: the `imp` entry of the bond-end blocks (2 per end).
        pub(in crate::gpu) const IMP_V_BONDS: usize = 8;
        /// `imp_topo` header word: … of the external blocks (2 per external entry).
        pub(in crate::gpu) const IMP_V_EXTERNALS: usize = 9;
        /// `imp_topo` header word: … of the angle blocks (ANGLE_VEC4 per angle).
        pub(in crate::gpu) const IMP_V_ANGLES: usize = 10;
        /// `imp_topo` header word: … of the last solve's report.
        pub(in crate::gpu) const IMP_V_REPORT: usize = 11;
        /// `imp_topo` header word: the number of constrained bonds.
        pub(in crate::gpu) const IMP_CONSTRAINTS: usize = 12;
        /// `imp_topo` header word: offset of their ends (i, j).
        pub(in crate::gpu) const IMP_OFF_CONSTRAINTS: usize = 13;
        /// `imp_topo` header word: offset of each particle's start of its constraint slots (n + 1).
        pub(in crate::gpu) const IMP_OFF_CSLOT_START: usize = 14;
        /// `imp_topo` header word: offset of the constraint slots (constraint index, J_END where the particle is its j).
        pub(in crate::gpu) const IMP_OFF_CSLOTS: usize = 15;
        /// `imp_topo` header word: the `imp` entry of the constraints' vectors (CONSTRAINT_VEC4 each).
        pub(in crate::gpu) const IMP_V_CONSTRAINTS: usize = 16;
        /// `imp_topo` header word: … of the volume elements' blocks (TETRA_VEC4 per element).
        pub(in crate::gpu) const IMP_V_TETRAS: usize = 17;
        /// `imp_topo` header word: … of the faces' blocks (FACE_VEC4 per face of the surface pack).
        pub(in crate::gpu) const IMP_V_FACES: usize = 18;
        /// `imp_topo` header word: … per packed body, (w_V, w_A, ∇V·v, ∇A·v).
        pub(in crate::gpu) const IMP_V_BODIES: usize = 19;
        /// `imp_topo` header word: … per curvature node, (w, β, g·v).
        pub(in crate::gpu) const IMP_V_NODES: usize = 20;
        /// `imp_topo` header word: … of the split solve's scalars and partial sums (implicit_split.wgsl).
        pub(in crate::gpu) const IMP_V_SPLIT: usize = 21;
        /// `imp` entries of an angle's 9×9 block.
        pub(in crate::gpu) const ANGLE_VEC4: usize = 21;
        /// `imp` entries of a volume element's 12×12 block.
        pub(in crate::gpu) const TETRA_VEC4: usize = 36;
        /// `imp` entries of a face's 9×9 block (its body's surface terms).
        pub(in crate::gpu) const FACE_VEC4: usize = 21;
        /// `imp` entries of a constraint (û and its flag; μ, r, p, q of the inner
        /// CG; its z, S's inverse diagonal and its tension).
        pub(in crate::gpu) const CONSTRAINT_VEC4: usize = 3;
        /// Slot bit: the particle is the constraint's second end.
        pub(in crate::gpu) const J_END: u32 = 0x8000_0000;
    }
}

/// Shared by src/gpu/implicit_split.rs and its kernels.
pub(super) mod implicit_split {
    shared_constants! {
        /// Split-solve entry (from `imp_topo[IMP_V_SPLIT]`): (r·z, α, threshold = tolerance·|b|, |b|).
        pub(in crate::gpu) const SPLIT_SCALARS: usize = 0;
        /// Split-solve entry: (iterations (bits), done (bits), |r|, the section the products multiply (bits)).
        pub(in crate::gpu) const SPLIT_STATE: usize = 1;
        /// Split-solve entry: `implicit_split_alpha`'s copy for `implicit_split_direction`: (r·z, iterations (bits), done (bits), 0).
        pub(in crate::gpu) const SPLIT_COPY: usize = 2;
        /// Split-solve entries from here: one per workgroup of a particle kernel.
        pub(in crate::gpu) const SPLIT_PARTIALS: usize = 3;
        /// Halt bit: a step outran its iteration budget (the host takes it again with a larger one).
        pub(in crate::gpu) const HALT_BUDGET: u32 = 512;
    }
}

/// Shared by src/gpu/kinetics.rs and its kernels.
pub(super) mod kinetics {
    use super::WgslConst;
    use crate::gpu::prelude::pack::PARAM_SLOTS;
    use crate::kinetics_engine::{COARSE_RATE_DT, STREAM_KINETICS, STREAM_QUENCHED};

    shared_constants! {
        /// Rules a bond type may combine with kinetics on the device.
        pub const RULES_PER_TYPE: usize = 4;
        /// `kin` header word: offset of the bond records (KIN_BOND_WORDS each).
        pub(in crate::gpu) const KIN_BONDS: usize = 0;
        /// `kin` header word: offset of the bound flags (1 each).
        pub(in crate::gpu) const KIN_BOUND: usize = 1;
        /// `kin` header word: offset of the ages (f64 bits: high, low).
        pub(in crate::gpu) const KIN_AGE: usize = 2;
        /// `kin` header word: offset of tension, length, k·dt (f32 bits).
        pub(in crate::gpu) const KIN_MEASURE: usize = 3;
        /// `kin` header word: offset of this step's event kinds (1 each).
        pub(in crate::gpu) const KIN_FLAG: usize = 4;
        /// `kin` header word: offset of the per-block event counts, then bases.
        pub(in crate::gpu) const KIN_BLOCK: usize = 5;
        /// `kin` header word: offset of the bond-type records (KIN_TYPE_WORDS each).
        pub(in crate::gpu) const KIN_TYPE: usize = 6;
        /// `kin` header word: offset of the exclusion tags (kinetic bond, or none).
        pub(in crate::gpu) const KIN_EXCL: usize = 7;
        /// `kin` header word: offset of the events (KIN_EVENT_WORDS each).
        pub(in crate::gpu) const KIN_EVENTS: usize = 8;
        /// `kin` header word: events written since the host last drained.
        pub(in crate::gpu) const KIN_CURSOR: usize = 9;
        /// `kin` header words: dt as f64 bits (high, low).
        pub(in crate::gpu) const KIN_DT_HI: usize = 10;
        pub(in crate::gpu) const KIN_DT_LO: usize = 11;
        /// `kin` header words: dt and kT as f32 bits.
        pub(in crate::gpu) const KIN_DT: usize = 12;
        pub(in crate::gpu) const KIN_KT: usize = 13;
        /// Words per kinetic record: i, j, bond type, bond index, term, rest length (f32 bits).
        pub(in crate::gpu) const KIN_BOND_WORDS: usize = 6;
        /// The first rule's word in a bond type's record, after its rule count, warned flag,
        /// warned bond, step lo, step hi, k·dt and 2 spare words.
        pub(in crate::gpu) const KIN_TYPE_RULES: usize = 8;
        /// Words per rule in a bond type's record: its code, then PARAM_SLOTS parameters (f32 bits).
        pub(in crate::gpu) const KIN_RULE_STRIDE: usize = 1 + PARAM_SLOTS;
        /// Words per bond type: the header, then RULES_PER_TYPE rules.
        pub(in crate::gpu) const KIN_TYPE_WORDS: usize = KIN_TYPE_RULES + RULES_PER_TYPE * KIN_RULE_STRIDE;
        /// Words per event: step lo, step hi, bond index, kind, tension, length, age hi, age lo.
        pub(in crate::gpu) const KIN_EVENT_WORDS: usize = 8;
        /// No record, no bond, no step.
        pub(in crate::gpu) const KIN_NONE: u32 = u32::MAX;
        /// Event kinds in the event words.
        pub(in crate::gpu) const EVENT_BREAK: u32 = 1;
        pub(in crate::gpu) const EVENT_REBIND: u32 = 2;
        pub(in crate::gpu) const EVENT_FORM: u32 = 3;
        ;
        // The CPU's Philox streams and coarse-step bound (src/kinetics_engine/engine.rs).
        WgslConst::u32("STREAM_KINETICS", STREAM_KINETICS),
        WgslConst::u32("STREAM_QUENCHED", STREAM_QUENCHED),
        WgslConst::f32("COARSE_RATE_DT", COARSE_RATE_DT),
    }
}

/// Shared by src/gpu/bind.rs and its kernels.
pub(super) mod bind {
    use super::WgslConst;

    shared_constants! {
        /// `kin` header word (after kinetics.rs's): offset of each particle's slot base (KIN_NONE: takes no part).
        pub(in crate::gpu) const KIN_SLOT_OF: usize = 16;
        /// `kin` header word: offset of the slots (pool records, KIN_NONE: free).
        pub(in crate::gpu) const KIN_SLOTS: usize = 17;
        /// `kin` header word: slots per particle (0: no `bind` on the device).
        pub(in crate::gpu) const KIN_SLOT_WIDTH: usize = 18;
        /// `kin` header word: offset of the rule records (KIN_RULE_WORDS each).
        pub(in crate::gpu) const KIN_RULES: usize = 19;
        /// `kin` header word: the number of rules.
        pub(in crate::gpu) const KIN_RULE_COUNT: usize = 20;
        /// `kin` header word: offset of each particle's body (KIN_NONE: none).
        pub(in crate::gpu) const KIN_BODY: usize = 21;
        /// `kin` header word: the next free pool record.
        pub(in crate::gpu) const KIN_POOL_NEXT: usize = 22;
        /// `kin` header word: the end of the pool (= the kinetic records).
        pub(in crate::gpu) const KIN_POOL_END: usize = 23;
        /// `kin` header word: the model bond index of the next new bond.
        pub(in crate::gpu) const KIN_NEXT_BOND: usize = 24;
        /// `kin` header word: offset of the candidates (i, j, rule).
        pub(in crate::gpu) const KIN_CAND: usize = 25;
        /// `kin` header word: the candidates the list holds.
        pub(in crate::gpu) const KIN_CAND_CAP: usize = 26;
        /// `kin` header word: offset of the per-particle candidate counts.
        pub(in crate::gpu) const KIN_CAND_N: usize = 27;
        /// `kin` header word: offset of the per-block counts, then bases.
        pub(in crate::gpu) const KIN_CAND_BLOCK: usize = 28;
        /// `kin` header word: this step's candidates.
        pub(in crate::gpu) const KIN_CAND_TOTAL: usize = 29;
        /// `kin` header word: 1 where this step's formation is left to the host.
        pub(in crate::gpu) const KIN_DEFER: usize = 30;
        /// `kin` header word: Σ max_bonds over the rules, the most new bonds of one particle in a step.
        pub(in crate::gpu) const KIN_MAX_GAIN: usize = 31;
        /// Words per rule record: type a, type b, bond type, max_bonds, between bodies, capture, k_on, rest (f32 bits).
        pub(in crate::gpu) const KIN_RULE_WORDS: usize = 8;
        /// `bind` rules the device takes.
        pub(in crate::gpu) const BIND_RULES: usize = 4;
        ;
        // The CPU's key salt of formation decisions (src/kinetics_engine/formation.rs).
        WgslConst::u32("FORMATION_SALT", crate::kinetics_engine::FORMATION_SALT),
    }
}

/// Shared by src/gpu/shake.rs and its kernels.
pub(super) mod shake {
    shared_constants! {
        /// `shake_topo` header word: the number of constraints.
        pub(in crate::gpu) const SH_COUNT: usize = 0;
        /// `shake_topo` header word: the number of colours.
        pub(in crate::gpu) const SH_COLORS: usize = 1;
        /// `shake_topo` header word: offset of each colour's first record (colours + 1).
        pub(in crate::gpu) const SH_OFF_COLOR_START: usize = 2;
        /// `shake_topo` header word: offset of the records (i, j, r0 bits, index in the deck's list), by colour.
        pub(in crate::gpu) const SH_OFF_RECORDS: usize = 3;
        /// `shake_topo` header word: the sweep cap.
        pub(in crate::gpu) const SH_MAX_SWEEPS: usize = 4;
        /// `shake_topo` header word: the largest |r − r0|/r0 accepted (f32 bits).
        pub(in crate::gpu) const SH_TOLERANCE: usize = 5;
        /// `shake_topo` header word: offset of the constrained particles.
        pub(in crate::gpu) const SH_OFF_PARTICLES: usize = 6;
        /// `shake_topo` header word: their number.
        pub(in crate::gpu) const SH_PARTICLES: usize = 7;
    }
}

/// Shared by src/gpu/surface.rs and its kernels.
pub(super) mod surface {
    shared_constants! {
        /// Words per face record: corners, body, the corners' body nodes (or
        /// NO_NODE without a curvature law), padding.
        pub(in crate::gpu) const FACE_WORDS: usize = 8;
        /// Words per edge record: ends, wings (particles), the ends' body nodes, body, padding.
        pub(in crate::gpu) const EDGE_WORDS: usize = 8;
        /// A face corner's body node without a curvature law.
        pub(in crate::gpu) const NO_NODE: u32 = u32::MAX;
    }
}

/// Shared by src/gpu/tetra.rs and its kernels.
pub(super) mod tetra {
    shared_constants! {
        /// Words of an element record in `topo`: its four corners and its term.
        pub(in crate::gpu) const TETRA_WORDS: usize = 5;
        /// Floats of an element's rest shape in `fparams`: D_m⁻¹ by columns, then V_0.
        pub(in crate::gpu) const TETRA_REST_FLOATS: usize = 10;
    }
}

/// Shared by src/gpu/protocol.rs and its kernels.
pub(super) mod protocol {
    shared_constants! {
        /// Words of a driven indenter's record.
        pub(in crate::gpu) const DRIVE_WORDS: usize = 16;
    }
}
/// The Philox generator's constants and noise streams (src/rng.rs).
pub(super) static RNG: &[WgslConst] = &[
    WgslConst::u32("PHILOX_M0", crate::rng::PHILOX_M0),
    WgslConst::u32("PHILOX_M1", crate::rng::PHILOX_M1),
    WgslConst::u32("PHILOX_W0", crate::rng::PHILOX_W0),
    WgslConst::u32("PHILOX_W1", crate::rng::PHILOX_W1),
    WgslConst::u32("STREAM_NOISE", crate::rng::STREAM_NOISE),
    WgslConst::u32("STREAM_NOISE_GAUSSIAN", crate::rng::STREAM_NOISE_GAUSSIAN),
    WgslConst::f32("SQRT_12", crate::rng::SQRT_12),
];

/// The tables of constants the prelude declares, one per group.
pub(super) static TABLES: &[&[WgslConst]] = &[
    pack::WGSL,
    status::WGSL,
    context::WGSL,
    contact::WGSL,
    fire::WGSL,
    implicit::WGSL,
    implicit_split::WGSL,
    kinetics::WGSL,
    bind::WGSL,
    shake::WGSL,
    surface::WGSL,
    tetra::WGSL,
    protocol::WGSL,
    RNG,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declarations_are_wgsl() {
        assert_eq!(WgslConst::u32("A", 7).declaration(), "const A: u32 = 7u;\n");
        assert_eq!(WgslConst::u32("B", u32::MAX).declaration(), "const B: u32 = 0xffffffffu;\n");
        assert_eq!(WgslConst::f32("C", 0.4).declaration(), "const C: f32 = 0.4;\n");
        assert_eq!(WgslConst::f32("D", 1.0).declaration(), "const D: f32 = 1.0;\n");
    }
}
