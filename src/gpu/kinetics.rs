//! Bond kinetics decided on the device (kernels: shaders/common/kinetics.wgsl).
//!
//! For models whose every kinetic rule has a device form
//! ([`crate::kinetics::Effect::gpu_form`]: a rate in closed form of the
//! bond's tension, a threshold, or rebinding to the same partner; today
//! `slip`, `catch_slip`, `cadherin`, `threshold` and `rebind`, each with its
//! evaluator beside it, `src/kinetics/NAME.wgsl`, dispatched by its registry
//! code, src/gpu/shader.rs) each step's breaks and
//! rebinds are decided on the GPU, with no read-back: the tension dE/dr and
//! length of every kinetic bond are measured at x_s after the force pass, and
//! after the step each bond draws the CPU's Philox number (seed, s, bond
//! index, stream 2) and compares it with 1 − exp(−k(F)·Δt) (f32; the CPU's
//! decision differs only where the uniform falls within ~1e-7·p of p), Δt =
//! s·dt the step's actual length (s < 1 where the contact step clamp of
//! src/gpu/contact.rs shortened it, read from the clamp's reduction word).
//! Bound flags and ages live in device buffers: ages as f64 bits, advanced by
//! the CPU's step length `fraction * dt` (the fraction widened from the
//! device's f32 s) with an exact integer f64 product and addition, so they
//! are the bits the host's clock gives; unbound bonds exert no force and
//! stop excluding their pair, and a step with events has the neighbour list
//! rebuilt. Events (step, bond, kind, tension, length, age) are compacted in
//! bond order by a per-block count, a one-workgroup scan and a ranked write,
//! so the event buffer is the same whatever the GPU's scheduling. The host
//! drains it ([`GpuBackend::drain_kinetics`]) at every synchronisation
//! (thermo, dump, checkpoint, the end, every 1000 steps) or when it could not
//! take another step's events (the run halts there and resumes); it then
//! counts, logs and applies the events and reads the ages back with the
//! positions.
//!
//! Which models: [`refusal`] says why a model's kinetics stay on the host
//! (one GPU step per segment, as before): the `bind` rules that
//! [`super::bind::refusal`] names (other `bind` formation runs on the
//! device, src/gpu/bind.rs, in pool records after the kinetic bonds), the rules
//! without a device form (those that change a bond's law every step or at a
//! strain: `motor`, `ratchet`, `maturation`, `plastic`), more than [`RULES_PER_TYPE`] rules on a bond
//! type, `special_bonds` 1-3 or 1-4 weights other than 1 with pair terms (the
//! exclusions of a broken bond would reach beyond its pair), or two bonds
//! joining the same pair where one has kinetic rules.
//!
//! # The `kin` buffer (u32 words)
//!
//! A header of 32 words (word indices as the `KIN_*` constants of
//! `prelude::kinetics`, 16–31 those of `prelude::bind`; both generated into
//! the program's prelude, src/gpu/prelude.rs), then: per kinetic record (the
//! bonds with a term of their own, in bond order, then `bind`'s pool) its
//! record (i, j, bond type, bond index, term, rest length), bound flag, age
//! (high, low words of the f64), tension, length and k·dt (f32 bits) and this
//! step's event kind; per block of 256 bonds its event count, then its base;
//! per bond type its record (rule count, warned, the lowest bond over
//! k·dt = 0.1, that step, that k·dt, two spare words, then up to four rules as
//! a code and eight f32 parameters); per exclusion entry of the topology its
//! kinetic bond (or none); the events (step low, high, bond, kind, tension,
//! length, age high, low); then `bind`'s sections (src/gpu/bind.rs).

use super::backend::GpuBackend;
use super::pack::Packed;
pub use super::prelude::kinetics::RULES_PER_TYPE;
use super::prelude::kinetics::*;
use super::shader::rule_code;
use super::step::{Dispatcher, Over, Phase, StepFeature};
use crate::kinetics_engine::EventKind;
use crate::neighbor::Exclusions;
use crate::system::{BondState, Model};

const HEADER_WORDS: usize = 32;

/// Why the model's bond kinetics cannot be decided on the device (None: they can).
pub fn refusal(model: &Model) -> Option<String> {
    if let Some(why) = super::bind::refusal(model) {
        return Some(why);
    }
    for (t, kinetics) in model.bond_kinetics.iter().enumerate() {
        let label = &model.bond_types[t].label.text;
        if kinetics.rules.len() > RULES_PER_TYPE {
            return Some(format!("bond type `{label}` has more than {RULES_PER_TYPE} kinetic rules"));
        }
        if let Some(r) = kinetics.rules.iter().find(|r| rule_code(r.rule).is_none()) {
            return Some(format!("kinetic rule `{}` (bond type `{label}`)", r.rule.name()));
        }
    }
    if !model.pair_rules.is_empty() && model.special_bonds.weights[1..] != [1.0, 1.0] {
        return Some("`special_bonds` 1-3 or 1-4 weights other than 1 with pair terms".into());
    }
    let mut joined = std::collections::HashMap::new();
    for (b, &[i, j]) in model.bonds.iter().enumerate() {
        let kinetic = !model.bond_kinetics[model.bond_type[b] as usize].rules.is_empty();
        let (count, any_kinetic) = joined.entry((i.min(j), i.max(j))).or_insert((0, false));
        *count += 1;
        *any_kinetic |= kinetic;
        if *count > 1 && *any_kinetic {
            return Some("two bonds joining the same pair, one with kinetic rules".into());
        }
    }
    None
}

/// What the host keeps of the device kinetics' buffer.
pub(super) struct KinLayout {
    /// The model bond of each kinetic bond.
    own_bonds: Vec<u32>,
    header: [u32; HEADER_WORDS],
    types: usize,
    /// Events the buffer holds.
    pub(super) capacity: u32,
    /// The term of the first kinetic bond.
    pub(super) first_term: u32,
    /// `bind` formation's pool (src/gpu/bind.rs): its first record, and the
    /// model bond index its first new bond takes.
    pool_first: u32,
    bond_base: u32,
    /// Kinetic records: the kinetic bonds, then the pool.
    records: u32,
}

/// The kernels of kinetics.wgsl.
pub(super) struct KinKernels {
    pub(super) room: wgpu::ComputePipeline,
    pub(super) measure: wgpu::ComputePipeline,
    pub(super) decide: wgpu::ComputePipeline,
    pub(super) scan: wgpu::ComputePipeline,
    pub(super) emit: wgpu::ComputePipeline,
    pub(super) bind_count: wgpu::ComputePipeline,
    pub(super) bind_scan: wgpu::ComputePipeline,
    pub(super) bind_write: wgpu::ComputePipeline,
    pub(super) bind_accept: wgpu::ComputePipeline,
    pub(super) bind_halt: wgpu::ComputePipeline,
}

impl KinKernels {
    pub(super) fn new(pipeline: impl Fn(&str) -> wgpu::ComputePipeline) -> Self {
        Self {
            room: pipeline("kin_room"),
            measure: pipeline("kin_measure"),
            decide: pipeline("kin_decide"),
            scan: pipeline("kin_scan"),
            emit: pipeline("kin_emit"),
            bind_count: pipeline("bind_count"),
            bind_scan: pipeline("bind_scan"),
            bind_write: pipeline("bind_write"),
            bind_accept: pipeline("bind_accept"),
            bind_halt: pipeline("bind_halt"),
        }
    }
}

/// Bond kinetics on the device as a step feature: the buffer's layout and the kernels.
pub(super) struct DeviceKinetics {
    pub(super) layout: KinLayout,
    pub(super) kernels: KinKernels,
}

impl DeviceKinetics {
    /// The decision's kernels (and `bind` formation's), each timed alone by `profile`.
    pub(super) fn profiled(&self) -> Vec<(&wgpu::ComputePipeline, Over)> {
        let (k, bonds) = (&self.kernels, Over::each(self.layout.bonds()));
        let mut passes = vec![(&k.measure, bonds), (&k.decide, bonds), (&k.scan, Over::Groups(1)), (&k.emit, bonds)];
        if self.layout.binds() {
            passes.extend(self.formation());
        }
        passes
    }

    /// `bind` formation's kernels after the decisions (src/gpu/bind.rs).
    fn formation(&self) -> [(&wgpu::ComputePipeline, Over); 4] {
        let k = &self.kernels;
        [(&k.bind_count, Over::Chunks), (&k.bind_scan, Over::Groups(1)), (&k.bind_write, Over::Chunks), (&k.bind_accept, Over::Groups(1))]
    }
}

impl StepFeature for DeviceKinetics {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        let (k, bonds) = (&self.kernels, Over::each(self.layout.bonds()));
        match phase {
            Phase::Start => at.dispatch(pass, &k.room, Over::Groups(1)),
            Phase::BeforeMove => at.dispatch(pass, &k.measure, bonds),
            Phase::AfterCommit => {
                at.dispatch_all(pass, &[(&k.decide, bonds), (&k.scan, Over::Groups(1)), (&k.emit, bonds)]);
                if self.layout.binds() {
                    at.dispatch_all(pass, &self.formation());
                }
            }
            Phase::End if self.layout.binds() => at.dispatch(pass, &k.bind_halt, Over::Groups(1)),
            _ => {}
        }
    }
}

/// Events and warnings the device decided since the host last drained it.
#[derive(Clone, Debug, Default)]
pub struct DeviceDecisions {
    /// In step order, then bond order.
    pub events: Vec<DeviceEvent>,
    /// (bond type, step, k·dt) of each type newly over k·dt = 0.1.
    pub coarse: Vec<(usize, u64, f64)>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceEvent {
    pub step: u64,
    pub bond: usize,
    pub kind: EventKind,
    /// A formed bond's type and particles.
    pub formed: Option<(u32, [u32; 2])>,
    pub force: f64,
    pub length: f64,
    pub age: f64,
}

fn f64_words(x: f64) -> [u32; 2] {
    let bits = x.to_bits();
    [(bits >> 32) as u32, bits as u32]
}

impl KinLayout {
    /// The `kin` buffer for `model` at `bonds`, packed as `packed` (with
    /// every bond bound) and its `exclusions`; `warned`: the bond types
    /// already warned about a coarse step.
    pub(super) fn pack(
        model: &Model,
        bonds: &BondState,
        packed: &Packed,
        exclusions: &Exclusions,
        dt: f64,
        kt: f64,
        warned: &[bool],
    ) -> (Vec<u32>, Self) {
        let own = &packed.own_bonds;
        let bind = super::bind::BindSizes::of(model);
        let count = own.len() + bind.pool;
        let blocks = count.div_ceil(super::context::WORKGROUP as usize);
        let capacity = 2 * count + 1024 + bind.candidates;
        let mut header = [0u32; HEADER_WORDS];
        // The sections at header words KIN_BONDS … KIN_TYPE, in that order.
        let sizes = [KIN_BOND_WORDS * count, count, 2 * count, 3 * count, count, 2 * blocks, KIN_TYPE_WORDS * model.bond_types.len()];
        let mut at = HEADER_WORDS;
        for (k, size) in sizes.iter().enumerate() {
            header[k] = at as u32;
            at += size;
        }
        let mut words = vec![0u32; at];
        // Bonds, bound flags, ages.
        let kinetic_of = {
            let mut of = vec![KIN_NONE; model.bonds.len()];
            own.iter().enumerate().for_each(|(k, &b)| of[b as usize] = k as u32);
            of
        };
        // Pool records not yet taken: i = none (src/gpu/bind.rs).
        for k in own.len()..count {
            let at = header[KIN_BONDS] as usize + KIN_BOND_WORDS * k;
            words[at..at + KIN_BOND_WORDS].fill(KIN_NONE);
        }
        for (k, &b) in own.iter().enumerate() {
            let b = b as usize;
            let [i, j] = model.bonds[b];
            let rest = model.rest_length(b, Some(bonds)) as f32;
            let record = [i, j, model.bond_type[b], b as u32, packed.first_own_term + k as u32, rest.to_bits()];
            let at = header[KIN_BONDS] as usize + KIN_BOND_WORDS * k;
            words[at..at + KIN_BOND_WORDS].copy_from_slice(&record);
            words[header[KIN_BOUND] as usize + k] = bonds.bound[b] as u32;
            let age = header[KIN_AGE] as usize + 2 * k;
            words[age..age + 2].copy_from_slice(&f64_words(bonds.age[b]));
        }
        // Bond types and their rules.
        for (t, kinetics) in model.bond_kinetics.iter().enumerate() {
            let at = header[KIN_TYPE] as usize + KIN_TYPE_WORDS * t;
            words[at] = kinetics.rules.len() as u32;
            words[at + 1] = warned.get(t).is_some_and(|&w| w) as u32;
            words[at + 2] = KIN_NONE;
            for (r, rule) in kinetics.rules.iter().enumerate() {
                let slot = at + KIN_TYPE_RULES + KIN_RULE_STRIDE * r;
                words[slot] = rule_code(rule.rule).expect("refusal() checked the rules");
                for (q, &p) in rule.params.iter().enumerate() {
                    words[slot + 1 + q] = (p as f32).to_bits();
                }
            }
        }
        // Exclusion tags: an entry holds while its kinetic bond is bound.
        header[KIN_EXCL] = words.len() as u32;
        let mut tag = std::collections::HashMap::new();
        for (b, &[i, j]) in model.bonds.iter().enumerate() {
            let kinetic = !model.bond_kinetics[model.bond_type[b] as usize].rules.is_empty();
            tag.insert((i.min(j), i.max(j)), if kinetic { kinetic_of[b] } else { KIN_NONE });
        }
        for i in 0..model.len() as u32 {
            for &j in exclusions.partners(i) {
                words.push(tag.get(&(i.min(j), i.max(j))).copied().unwrap_or(KIN_NONE));
            }
        }
        header[KIN_EVENTS] = words.len() as u32;
        words.resize(words.len() + KIN_EVENT_WORDS * capacity, 0);
        let [dt_hi, dt_lo] = f64_words(dt);
        header[KIN_DT_HI] = dt_hi;
        header[KIN_DT_LO] = dt_lo;
        header[KIN_DT] = (dt as f32).to_bits();
        header[KIN_KT] = (kt as f32).to_bits();
        super::bind::append(model, &bind, count, &mut words, &mut header);
        words[..HEADER_WORDS].copy_from_slice(&header);
        let layout = Self {
            own_bonds: own.clone(),
            header,
            types: model.bond_types.len(),
            capacity: capacity as u32,
            first_term: packed.first_own_term,
            pool_first: own.len() as u32,
            bond_base: model.bonds.len() as u32,
            records: count as u32,
        };
        (words, layout)
    }

    pub(super) fn bonds(&self) -> u32 {
        self.records
    }

    /// Whether `bind` formation runs on the device (src/gpu/bind.rs).
    pub(super) fn binds(&self) -> bool {
        self.records > self.pool_first
    }

    /// The pool record of a bond formed on the device.
    fn pool_record(&self, bond: usize) -> u64 {
        (self.pool_first as usize + bond - self.bond_base as usize) as u64
    }
}

impl GpuBackend {
    /// The events and coarse-step warnings decided on the device since the
    /// last call (empty without device kinetics); the event buffer is
    /// emptied. Reads one word when there were none.
    pub fn drain_kinetics(&self) -> DeviceDecisions {
        let mut out = DeviceDecisions::default();
        let Some(kinetics) = self.device_kinetics() else { return out };
        let header = kinetics.header;
        let (types_at, types) = (header[KIN_TYPE] as u64, kinetics.types);
        let count = self.read_kin(KIN_CURSOR as u64, 1)[0] as usize;
        if count > 0 {
            let words = self.read_kin(header[KIN_EVENTS] as u64, (KIN_EVENT_WORDS * count) as u64);
            let formed = self.formed_records(&words);
            for e in words.chunks_exact(KIN_EVENT_WORDS) {
                let kind = match e[3] {
                    EVENT_BREAK => EventKind::Break,
                    EVENT_REBIND => EventKind::Rebind,
                    EVENT_FORM => EventKind::Form,
                    other => unreachable!("event kind {other} from the device"),
                };
                let bond = e[2] as usize;
                out.events.push(DeviceEvent {
                    step: (e[1] as u64) << 32 | e[0] as u64,
                    bond,
                    kind,
                    formed: (kind == EventKind::Form).then(|| formed(bond)),
                    force: f32::from_bits(e[4]) as f64,
                    length: f32::from_bits(e[5]) as f64,
                    age: f64::from_bits((e[6] as u64) << 32 | e[7] as u64),
                });
            }
            self.write_kin(KIN_CURSOR as u64, &[0]);
        }
        let records = self.read_kin(types_at, (KIN_TYPE_WORDS * types) as u64);
        for (t, r) in records.chunks_exact(KIN_TYPE_WORDS).enumerate() {
            if r[1] == 1 && r[2] != KIN_NONE {
                out.coarse.push((t, (r[4] as u64) << 32 | r[3] as u64, f32::from_bits(r[5]) as f64));
                self.write_kin(types_at + (KIN_TYPE_WORDS * t) as u64 + 2, &[KIN_NONE]);
            }
        }
        out
    }

    /// The device's bound flags and ages written into `bonds` (the kinetic
    /// bonds', and those of the bonds formed on the device that the host has
    /// drained; nothing without device kinetics).
    pub fn download_bond_state(&self, bonds: &mut BondState) {
        let Some(kinetics) = self.device_kinetics() else { return };
        let formed = bonds.len().saturating_sub(kinetics.bond_base as usize).min((kinetics.records - kinetics.pool_first) as usize);
        let n = kinetics.own_bonds.len() as u64 + formed as u64;
        let bound = self.read_kin(kinetics.header[KIN_BOUND] as u64, n);
        let ages = self.read_kin(kinetics.header[KIN_AGE] as u64, 2 * n);
        let pool = (0..formed).map(|f| kinetics.bond_base + f as u32);
        for (k, b) in kinetics.own_bonds.iter().copied().chain(pool).enumerate() {
            bonds.bound[b as usize] = bound[k] == 1;
            bonds.age[b as usize] = f64::from_bits((ages[2 * k] as u64) << 32 | ages[2 * k + 1] as u64);
        }
    }

    /// The type and particles of each bond formed on the device among the
    /// event words `events`, read from their pool records in one read.
    fn formed_records(&self, events: &[u32]) -> impl Fn(usize) -> (u32, [u32; 2]) {
        let kinetics = self.device_kinetics().expect("events come from device kinetics");
        // Formed bonds take consecutive indices, in event order.
        let formed: Vec<usize> = events.chunks_exact(KIN_EVENT_WORDS).filter(|e| e[3] == EVENT_FORM).map(|e| e[2] as usize).collect();
        let first = formed.first().copied().unwrap_or(0);
        let records = match formed.last() {
            Some(&last) => self.read_kin(
                kinetics.header[KIN_BONDS] as u64 + KIN_BOND_WORDS as u64 * kinetics.pool_record(first),
                (KIN_BOND_WORDS * (last - first + 1)) as u64,
            ),
            None => Vec::new(),
        };
        move |bond: usize| {
            let r = &records[KIN_BOND_WORDS * (bond - first)..];
            (r[2], [r[0], r[1]])
        }
    }
}
