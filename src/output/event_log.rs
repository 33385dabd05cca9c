//! The bond-event log: the CSV file of `events FILE` in a deck has one row
//! per event: `step,time[s],event,bond,type,i,j,force[pN],length[µm],age[s]` — `event` is
//! `break`, `rebind`, `form` or `reset`, `bond` the bond's index (0-based, in
//! topology order, new bonds appended), `i j` the particle ids, `force` the
//! tension the bond carried (dE/dr, positive when stretched) and `length` its
//! length when the event was decided, `age` the time the bond had been bound
//! through the end of that step (a break's age is the bond's lifetime, to
//! within the step in which it broke; rebinds and formations have age 0).
//!
//! Rows reach the file in whole steps, batched: at most
//! [`BATCH_INTERVAL`](super::records::BATCH_INTERVAL) (1 s) of wall time or
//! 64 KiB after they were decided, and at the end of the run; a SIGKILL
//! loses at most that last batch, never part of a row.

use std::fs::File;
use std::io::Write;

use super::records::RecordFile;

use crate::kinetics_engine::Event;
use crate::units::{Dim, UnitSystem};

/// The CSV event file.
pub struct EventLog {
    out: RecordFile,
}

impl EventLog {
    pub fn create(file: File, units: UnitSystem) -> std::io::Result<Self> {
        let mut out = RecordFile::new(file);
        writeln!(
            out,
            "step,time[{}],event,bond,type,i,j,force[{}],length[{}],age[{}]",
            units.label(Dim::Time),
            units.label(Dim::Force),
            units.label(Dim::Length),
            units.label(Dim::Time)
        )?;
        out.commit()?;
        Ok(Self { out })
    }

    pub fn write(&mut self, events: &[Event]) -> std::io::Result<()> {
        for e in events {
            writeln!(
                self.out,
                "{},{:e},{},{},{},{},{},{:e},{:e},{:e}",
                e.step,
                e.time,
                e.kind.name(),
                e.bond,
                e.bond_type,
                e.particles[0],
                e.particles[1],
                e.force,
                e.length,
                e.age
            )?;
        }
        self.out.commit_batched()
    }

    /// Writes the rows that have waited their interval (called once per
    /// step, so a batch is bounded in time even when no new event comes).
    pub fn flush_due(&mut self) -> std::io::Result<()> {
        self.out.commit_batched()
    }

    pub fn finish(mut self) -> std::io::Result<()> {
        self.out.finish()
    }
}
