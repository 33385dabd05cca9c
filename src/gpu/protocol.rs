//! The protocols of a run on the device (the CPU's: src/run/protocol.rs):
//! held coordinates (`freeze`), moving groups (`move`) and parameter ramps.
//!
//! - **Held coordinates**: one word per particle (its held axes and moving
//!   group) in the `protocol` buffer (binding 14). A held axis takes no drift
//!   (the integrator sees the force masked, as the CPU's does), its noise
//!   still counts in the contact step clamp and the blow-up check, and after
//!   the step it is put back where it was, position and image counter, so a
//!   frozen coordinate keeps its bits at any kT.
//! - **Moving groups**: a moved particle holds all three axes and then
//!   advances by v·dt with the full dt (as on the CPU, also in a clamped
//!   step), wrapped into the box. A constant velocity's v·dt is computed by
//!   the host in f64 and stored in the positions' fixed point, so the path is
//!   the CPU's to the fixed point's unit; a velocity field (`move … velocity`)
//!   is evaluated in f32 by a generated `mover_velocity` at the particle's
//!   unwrapped position before the step and the step's start time. A field
//!   that is not finite halts the step as a blow-up of that particle.
//! - **Ramps**: every `fparams` slot a ramp sets (its term's, and for a bond
//!   type the terms of its bonds that have their own parameters, except their
//!   own rest lengths) gets its value at every step from a table the host
//!   fills per segment with the CPU's f64 values rounded to f32; a small
//!   kernel copies the step's row into `fparams` before the step's forces. No
//!   read-back: with ramps a call is cut into chunks of at most [`RAMP_ROWS`]
//!   steps, each uploading its rows.
//!
//! - **Driven indenters** (`indent`): after each step's forces one workgroup
//!   sums each indenter's force on its members in a fixed order (strided
//!   partial sums, then a tree: the same bits every run) and holds the drive
//!   for good once the load's magnitude reaches the target, as the CPU checks
//!   after every step; after the step a moving drive's centre takes the next
//!   value of a table the host fills per call with the CPU's f64 sums
//!   x0 + v·dt + v·dt + …, rounded to f32. At the call's end the host reads
//!   how far each drive advanced and whether it holds (one small read).

use std::fmt::Write;

use glam::DVec3;

use super::pack::FixedPoint;
use super::prelude::protocol::*;
use super::step::{Dispatcher, Over, Phase, StepFeature};
use crate::expr::wgsl::wgsl;
use crate::expr::Expr;
use crate::system::{BondState, Model};

/// Rows of the device's ramp table: the longest chunk of a call with ramps
/// or driven indenters (a drive's table has one row more).
pub const RAMP_ROWS: u64 = 1024;

/// The index of each kind's first term in pack's order: bond types, angle
/// types, pair rules, externals, body rules.
fn term_bases(model: &Model) -> [usize; 5] {
    let b = model.bond_types.len();
    let a = b + model.angle_types.len();
    let p = a + model.pair_rules.len();
    [0, b, a, p, p + model.externals.len()]
}

/// One particle a protocol holds: its held axes and, for a moved particle,
/// its moving group (index into [`DeviceProtocol::movers`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldCoordinates {
    pub particle: u32,
    pub axes: [bool; 3],
    pub mover: Option<usize>,
}

/// A moving group's velocity.
#[derive(Clone, Debug)]
pub enum DeviceVelocity {
    Constant(DVec3),
    /// Expressions of the unwrapped position `x`, `y`, `z` and the time `t`.
    Field(Box<[Expr; 3]>),
}

/// A term whose parameter a ramp sets (indices into the model's tables).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TermRef {
    BondType(usize),
    AngleType(usize),
    PairRule(usize),
    External(usize),
    BodyRule(usize),
}

/// A driven indenter: the active external it moves (index into the
/// model's externals; its parameters `x`, `y`, `z` are the centre) and the
/// load that stops it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceDrive {
    pub external: usize,
    pub until: Option<f64>,
}

/// The protocols in force for a run, as the device takes them.
#[derive(Clone, Debug, Default)]
pub struct DeviceProtocol {
    /// Held particles, ascending.
    pub held: Vec<HeldCoordinates>,
    pub movers: Vec<DeviceVelocity>,
    /// Ramped parameters: (term, parameter index in its schema).
    pub ramps: Vec<(TermRef, usize)>,
    pub drives: Vec<DeviceDrive>,
}

/// The `mover_velocity` cases of the moving groups with velocity fields.
pub fn mover_cases(protocol: &DeviceProtocol) -> Result<String, String> {
    let name = |n: &str| match n {
        "x" | "y" | "z" => Some(format!("x.{n}")),
        "t" => Some("t".to_string()),
        _ => None,
    };
    let mut cases = String::new();
    for (m, velocity) in protocol.movers.iter().enumerate() {
        if let DeviceVelocity::Field(field) = velocity {
            let code = field
                .iter()
                .map(|e| wgsl(e, &name).map_err(|e| format!("the velocity field of a moving group on the GPU: {}", e.message)))
                .collect::<Result<Vec<_>, _>>()?;
            writeln!(cases, "        case {m}u: {{ return vec3<f32>({}, {}, {}); }}", code[0], code[1], code[2]).unwrap();
        }
    }
    Ok(cases)
}

/// What [`ProtocolPack::slots`] needs of a packing (src/gpu/pack.rs): the
/// first parameter slot, the bonds with their own terms and the first of those.
pub(super) struct PackedTerms<'a> {
    pub(super) params: u32,
    pub(super) own_bonds: &'a [u32],
    pub(super) first_own_term: u32,
}

/// The `protocol` buffer's layout and the host's ramp values.
pub(super) struct ProtocolPack {
    ramps: Vec<(TermRef, usize)>,
    /// The ramp of each ramped slot (after [`Self::slots`]).
    ramp_of_slot: Vec<usize>,
    /// Room for slots: every term a ramp could reach.
    slot_capacity: u32,
    /// The layout's words of `Params::protocol`.
    pub(super) fields: [u32; 8],
    /// The buffer's words at the start (held words, moving groups).
    pub(super) words: Vec<u32>,
    /// The ramps' values per step from a first step (`GpuBackend::set_ramps`).
    values: (u64, Vec<Vec<f64>>),
    /// Per drive: its centres from the current call's start (`GpuBackend::set_drives`),
    /// how far it advanced since, and whether it holds.
    drives: Vec<(Vec<DVec3>, u64, bool)>,
}

impl ProtocolPack {
    /// The buffer for `protocol` on a model of `n` particles stepped by `dt`.
    pub(super) fn new(protocol: &DeviceProtocol, model: &Model, dt: f64, fixed: &FixedPoint) -> Self {
        let n = model.len();
        let mut words = vec![0u32; if protocol.held.is_empty() { 0 } else { n }];
        for h in &protocol.held {
            let axes = (0..3).filter(|&a| h.axes[a]).map(|a| 1u32 << a).sum::<u32>();
            words[h.particle as usize] = axes | h.mover.map_or(0, |m| (m as u32 + 1) << 3);
        }
        let off_movers = words.len() as u32;
        for velocity in &protocol.movers {
            let (step, field) = match velocity {
                DeviceVelocity::Constant(v) => ((*v * dt).to_array().map(|d| fixed.encode(d)), 0),
                DeviceVelocity::Field(_) => ([(0, 0); 3], 1),
            };
            words.extend(step.iter().map(|s| s.0).chain(step.iter().map(|s| s.1)).chain([field, 0]));
        }
        let slot_capacity = protocol
            .ramps
            .iter()
            .map(|(term, _)| {
                1 + if let TermRef::BondType(t) = term { model.bond_type.iter().filter(|&&b| b as usize == *t).count() } else { 0 }
            })
            .sum::<usize>() as u32;
        let off_ramp_slots = words.len() as u32;
        let off_ramp_table = off_ramp_slots + slot_capacity;
        words.resize((off_ramp_table as u64 + RAMP_ROWS * slot_capacity as u64) as usize, 0);
        let off_drives = words.len();
        words.resize(off_drives + DRIVE_WORDS * protocol.drives.len(), 0);
        let bases = term_bases(model);
        for (d, drive) in protocol.drives.iter().enumerate() {
            let external = &model.externals[drive.external];
            let term = (bases[3] + drive.external) as u32;
            let members = words.len() as u32;
            words.extend(&external.members);
            let centre = ["x", "y", "z"].map(|a| {
                let k = crate::interactions::param_index(external.term.interaction, a).expect("an indenter has a centre");
                (super::pack::PARAM_SLOTS as u32) * term + k as u32
            });
            let table = words.len() as u32;
            words.resize(words.len() + 3 * (RAMP_ROWS as usize + 1), 0);
            let until = drive.until.unwrap_or(f64::INFINITY);
            let record =
                [term, members, members + external.members.len() as u32, 0, 0, u32::from(drive.until.is_some()), (until as f32).to_bits()];
            let at = off_drives + DRIVE_WORDS * d;
            words[at..at + 7].copy_from_slice(&record);
            words[at + 7..at + 10].copy_from_slice(&centre);
            words[at + 10] = table;
        }
        let held = u32::from(!protocol.held.is_empty());
        Self {
            ramps: protocol.ramps.clone(),
            ramp_of_slot: Vec::new(),
            slot_capacity,
            fields: [held, 0, 0, off_movers, off_ramp_slots, off_ramp_table, protocol.drives.len() as u32, off_drives as u32],
            words,
            values: (0, Vec::new()),
            drives: protocol.drives.iter().map(|_| (Vec::new(), 0, false)).collect(),
        }
    }

    /// The `fparams` slots the ramps set in a packing (with the bond state
    /// `bonds` it was packed with), recorded with their ramps; returns them
    /// as the words at `off_ramp_slots`.
    pub(super) fn slots(&mut self, model: &Model, packed: &PackedTerms, bonds: Option<&BondState>) -> Vec<u32> {
        let bases = term_bases(model);
        let slot = |term: usize, param: usize| packed.params + (super::pack::PARAM_SLOTS * term + param) as u32;
        let (mut slots, mut ramp_of_slot) = (Vec::new(), Vec::new());
        for (r, &(term, param)) in self.ramps.iter().enumerate() {
            let index = match term {
                TermRef::BondType(k) => bases[0] + k,
                TermRef::AngleType(k) => bases[1] + k,
                TermRef::PairRule(k) => bases[2] + k,
                TermRef::External(k) => bases[3] + k,
                TermRef::BodyRule(k) => bases[4] + k,
            };
            slots.push(slot(index, param));
            if let TermRef::BondType(t) = term {
                // Bonds with their own term take the type's parameters, but keep their own rest length.
                let own_rest = |b: usize| model.bond_kinetics[t].rest_index == Some(param) && bonds.is_some_and(|s| s.rest[b].is_some());
                for (j, &b) in packed.own_bonds.iter().enumerate() {
                    let b = b as usize;
                    if model.bond_type[b] as usize == t && !own_rest(b) {
                        slots.push(slot(packed.first_own_term as usize + j, param));
                    }
                }
            }
            ramp_of_slot.resize(slots.len(), r);
        }
        self.ramp_of_slot = ramp_of_slot;
        self.fields[1] = slots.len() as u32;
        slots
    }

    /// Starts a call: each drive's centres from the call's start (as many
    /// as the call has steps, and one) and whether it holds.
    pub(super) fn set_drives(&mut self, drives: Vec<(Vec<DVec3>, bool)>) {
        self.drives = drives.into_iter().map(|(centres, holding)| (centres, 0, holding)).collect();
    }

    /// Whether any drive moves an indenter.
    pub(super) fn drives(&self) -> bool {
        self.fields[6] > 0
    }

    /// The drives' records and tables for a chunk of `steps` steps, as
    /// (word offset, words) to write: each drive's state, then its centres
    /// from where it is.
    pub(super) fn drive_words(&self, steps: u64) -> Vec<(u32, Vec<u32>)> {
        let mut writes = Vec::new();
        for (d, (centres, advanced, holding)) in self.drives.iter().enumerate() {
            let at = self.fields[7] + (DRIVE_WORDS * d) as u32;
            writes.push((at + 3, vec![u32::from(*holding), 0]));
            let from = *advanced as usize;
            let rows = centres.get(from..(from + steps as usize + 1).min(centres.len())).expect("a drive's centres for every step");
            let table = self.words[at as usize + 10];
            writes.push((table, rows.iter().flat_map(|c| c.to_array().map(|v| (v as f32).to_bits())).collect()));
        }
        writes
    }

    /// The words of each drive's state (holding, advances) to read after a chunk.
    pub(super) fn drive_state_range(&self) -> (u32, u32) {
        (self.fields[7], (DRIVE_WORDS * self.drives.len()) as u32)
    }

    /// Records the drives' state words read after a chunk.
    pub(super) fn follow_drives(&mut self, state: &[u32]) {
        for (d, drive) in self.drives.iter_mut().enumerate() {
            drive.1 += u64::from(state[DRIVE_WORDS * d + 4]);
            drive.2 = state[DRIVE_WORDS * d + 3] != 0;
        }
    }

    /// Each drive's advances since the call started and whether it holds.
    pub(super) fn drive_states(&self) -> Vec<(u64, bool)> {
        self.drives.iter().map(|d| (d.1, d.2)).collect()
    }

    /// Whether any slot is ramped.
    pub(super) fn ramps(&self) -> bool {
        self.fields[1] > 0
    }

    /// Records the ramps' values (one row per step, in ramp order) from `first_step`.
    pub(super) fn set_values(&mut self, first_step: u64, rows: Vec<Vec<f64>>) {
        self.values = (first_step, rows);
    }

    /// The table rows of `steps` steps from `step` (at most [`RAMP_ROWS`]), as
    /// the words from `off_ramp_table`; sets the table's first step.
    pub(super) fn rows(&mut self, step: u64, steps: u64) -> Vec<u32> {
        let (first, rows) = &self.values;
        let from = step.checked_sub(*first).expect("ramp values from before the step") as usize;
        let rows = rows.get(from..from + steps as usize).expect("ramp values for every step of the call");
        self.fields[2] = step as u32;
        debug_assert!(self.ramp_of_slot.len() <= self.slot_capacity as usize);
        rows.iter().flat_map(|row| self.ramp_of_slot.iter().map(|&r| (row[r] as f32).to_bits())).collect()
    }
}

/// The protocols as a step feature: the ramped parameters' values of the
/// step at its start, and the driven indenters' load check before the move
/// and advance after the commit; each only where the layout has ramps or
/// drives (`Params::protocol`).
pub(super) struct ProtocolKernels {
    ramps: wgpu::ComputePipeline,
    drive_check: wgpu::ComputePipeline,
    drive_advance: wgpu::ComputePipeline,
}

impl ProtocolKernels {
    pub(super) fn new(pipeline: impl Fn(&str) -> wgpu::ComputePipeline) -> Self {
        Self {
            ramps: pipeline("protocol_ramps"),
            drive_check: pipeline("protocol_drive_check"),
            drive_advance: pipeline("protocol_drive_advance"),
        }
    }
}

impl StepFeature for ProtocolKernels {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        let (ramped, drives) = (at.params.protocol[1], at.params.protocol[6] > 0);
        match phase {
            Phase::Start if ramped > 0 => at.dispatch(pass, &self.ramps, Over::each(ramped)),
            Phase::BeforeMove if drives => at.dispatch(pass, &self.drive_check, Over::Groups(1)),
            Phase::AfterCommit if drives => at.dispatch(pass, &self.drive_advance, Over::Groups(1)),
            _ => {}
        }
    }
}
