//! The bond-lifetime table (`lifetimes FILE.csv` in a deck): τ per bond type
//! from the breaks the run has seen, rewritten atomically at the end of every
//! `run`.
//!
//! A bond that breaks while its step is decided was bound through the end of
//! that step: its recorded age a (see [`Event::age`]) overshoots the moment of
//! rupture by dt/2 on average, so each break contributes the lifetime
//! t = a − dt/2 (exact to O(k·dt²) for a constant rate k). Per bond type:
//!
//! | column | meaning | unit |
//! |---|---|---|
//! | `type` | bond type | — |
//! | `breaks` | breaks seen | — |
//! | `surviving` | bonds of the type still bound when the table was written | — |
//! | `force` | mean tension at rupture, F = dE/dr | force |
//! | `tau` | mean lifetime of the broken bonds, ⟨t⟩ | time |
//! | `stderr` | its standard error, sd(t)/√breaks | time |
//! | `tau_censored` | (Σ t over breaks + Σ age over survivors)/breaks: the maximum-likelihood τ of an exponential lifetime when some bonds outlive the run | time |
//!
//! With survivors left, `tau` underestimates a long lifetime (only the short
//! ones were seen) and `tau_censored` is the estimate to read. A bond that
//! rebinds starts a new lifetime at age 0. Statistics that need more breaks than were seen are `NaN`.

use std::io::{self, Write};
use std::path::Path;

use super::files::write_atomically;
use crate::kinetics_engine::{Event, EventKind};
use crate::system::{BondState, Model};
use crate::units::Dim;

/// Running sums of the breaks of one bond type.
#[derive(Clone, Debug, Default)]
struct TypeSums {
    breaks: u64,
    lifetime: f64,
    lifetime_sq: f64,
    force: f64,
}

/// Lifetimes of broken bonds, per bond type.
#[derive(Clone, Debug, Default)]
pub struct LifetimeTable {
    per_type: Vec<TypeSums>,
}

impl LifetimeTable {
    /// Adds the breaks among `events`, decided over a step of length `dt`.
    pub fn record(&mut self, model: &Model, events: &[Event], dt: f64) {
        self.per_type.resize(model.bond_types.len(), TypeSums::default());
        for e in events.iter().filter(|e| e.kind == EventKind::Break) {
            let sums = &mut self.per_type[model.bond_type[e.bond] as usize];
            let t = e.age - 0.5 * dt;
            sums.breaks += 1;
            sums.lifetime += t;
            sums.lifetime_sq += t * t;
            sums.force += e.force;
        }
    }

    /// Writes the table for every bond type with kinetic rules, atomically,
    /// through no link below `root` (the output directory).
    pub fn write(&self, root: &Path, path: &Path, model: &Model, bonds: Option<&BondState>) -> io::Result<()> {
        let units = model.units;
        write_atomically(root, path, |out| {
            writeln!(
                out,
                "type,breaks,surviving,force[{f}],tau[{t}],stderr[{t}],tau_censored[{t}]",
                f = units.label(Dim::Force),
                t = units.label(Dim::Time)
            )?;
            for ty in (0..model.bond_types.len()).filter(|&ty| !model.bond_kinetics[ty].rules.is_empty()) {
                let sums = self.per_type.get(ty).cloned().unwrap_or_default();
                let (mut surviving, mut surviving_age) = (0u64, 0.0);
                if let Some(bonds) = bonds {
                    for b in (0..bonds.len()).filter(|&b| bonds.bound[b] && model.bond_type[b] as usize == ty) {
                        surviving += 1;
                        surviving_age += bonds.age[b];
                    }
                }
                let n = sums.breaks as f64;
                let mean = sums.lifetime / n;
                let variance = (sums.lifetime_sq - n * mean * mean) / (n - 1.0);
                let stderr = (variance.max(0.0) / n).sqrt();
                let censored = (sums.lifetime + surviving_age) / n;
                writeln!(
                    out,
                    "{},{},{surviving},{:e},{mean:e},{stderr:e},{censored:e}",
                    model.bond_types[ty].label.text,
                    sums.breaks,
                    sums.force / n
                )?;
            }
            Ok(())
        })
    }
}
