//! The run log `NAME.log` in the output directory: what ran (version, git
//! hash, command line), what it read (the deck and force fields, as read),
//! the resolved parameters of each `run`, and where the time went.
//!
//! Every section goes to the file whole when written (see
//! [`records`](super::records)), so a killed run's log ends with its last
//! complete section. The closing table is LAMMPS' "MPI task
//! timing breakdown" for the CPU step loop:
//!
//! ```text
//! Section   |  time (s)  | %total
//! ----------+------------+-------
//! Force     |     12.345 |   80.1
//! Neigh     |      1.234 |    8.0
//! ...
//! ```
//!
//! [`PhaseTimes`] is filled by the step loop with one [`Instant`] per phase
//! boundary (a few tens of nanoseconds a step).

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::records::RecordFile;
use crate::forcefield::TermType;
use crate::input::DeckInputs;
use crate::system::Model;

/// Input files up to this size are copied into the log; larger ones (a big
/// topology) are named with their size.
const COPY_LIMIT: usize = 64 * 1024;

/// A phase of the step loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Force evaluation: pairs, bonds, angles, surfaces, contacts, externals.
    Force,
    /// Neighbour-list checks and rebuilds.
    Neighbor,
    /// The integrator's move (and constraint projection).
    Integrate,
    /// Bond kinetics and formation.
    Kinetics,
    /// Thermo, dumps and checkpoints.
    Output,
}

const PHASES: [(Phase, &str); 5] = [
    (Phase::Force, "Force"),
    (Phase::Neighbor, "Neigh"),
    (Phase::Integrate, "Integrate"),
    (Phase::Kinetics, "Kinetics"),
    (Phase::Output, "Output"),
];

/// Wall time spent in each phase of the step loop, and in the loops in all.
#[derive(Clone, Debug, Default)]
pub struct PhaseTimes {
    phases: [Duration; 5],
    /// Wall time of every `run` loop (CPU and GPU).
    pub total: Duration,
}

/// The start of the phase under way.
pub struct Clock(Instant);

impl Clock {
    /// Ends the phase under way, adding its time to `phase`.
    pub fn lap(&mut self, times: &mut PhaseTimes, phase: Phase) {
        let now = Instant::now();
        times.phases[phase as usize] += now - self.0;
        self.0 = now;
    }
}

impl PhaseTimes {
    pub fn clock(&self) -> Clock {
        Clock(Instant::now())
    }

    pub fn of(&self, phase: Phase) -> Duration {
        self.phases[phase as usize]
    }

    /// The breakdown table; "Other" is the loop time no phase accounts for
    /// (GPU steps, progress, stop checks).
    pub fn table(&self) -> String {
        let total = self.total.as_secs_f64();
        let share = |t: f64| if total > 0.0 { 100.0 * t / total } else { 0.0 };
        let mut out = String::from("Section   |  time (s)  | %total\n----------+------------+-------\n");
        let mut accounted = 0.0;
        for (phase, name) in PHASES {
            let t = self.of(phase).as_secs_f64();
            accounted += t;
            let _ = writeln!(out, "{name:<9} | {t:>10.3} | {:>6.1}", share(t));
        }
        let other = (total - accounted).max(0.0);
        let _ = writeln!(out, "{:<9} | {other:>10.3} | {:>6.1}", "Other", share(other));
        let _ = writeln!(out, "{:<9} | {total:>10.3} | {:>6.1}", "Total", share(total));
        out
    }
}

/// What the log's head says about the program.
#[derive(Clone, Debug)]
pub struct LogHeader {
    /// "cellmd VERSION (git HASH)".
    pub version: String,
    /// The command line, words separated by blanks.
    pub command_line: String,
}

/// The open log file.
pub struct RunLog {
    file: RecordFile,
    pub path: PathBuf,
}

impl RunLog {
    /// Writes the log's head — program, command line, input files — to
    /// `file` (empty, as opened for output), the log at `path`.
    pub fn create(file: File, path: &Path, header: &LogHeader, inputs: &DeckInputs) -> io::Result<Self> {
        let mut log = Self { file: RecordFile::new(file), path: path.to_path_buf() };
        let mut head = format!("{}\ncommand: {}\ndeck: {}\n", header.version, header.command_line, inputs.deck);
        for (name, value) in &inputs.vars {
            let _ = writeln!(head, "variable override: {name}={value}");
        }
        for file in &inputs.files {
            if file.text.len() <= COPY_LIMIT {
                let _ = write!(head, "\n---- {} ({} bytes, as read) ----\n{}", file.path, file.text.len(), file.text);
                if !file.text.ends_with('\n') {
                    head.push('\n');
                }
            } else {
                let _ = write!(head, "\n---- {} ({} bytes; larger than {COPY_LIMIT}, not copied) ----\n", file.path, file.text.len());
            }
        }
        log.section(&head)?;
        Ok(log)
    }

    /// Appends a block of text, written whole.
    pub fn section(&mut self, text: &str) -> io::Result<()> {
        self.file.write_all(text.as_bytes())?;
        if !text.ends_with('\n') {
            self.file.write_all(b"\n")?;
        }
        self.file.commit()
    }
}

/// The resolved parameters of every term of the model (after `coeff`
/// edits and externals), one line per bond type, angle type, pair rule,
/// surface and contact term, and external.
pub fn model_parameters(model: &Model) -> String {
    let mut out = String::new();
    let names = &model.type_names;
    let label = |t: &TermType| t.label.text.clone();
    let mut terms: Vec<(&str, String, &TermType)> = Vec::new();
    terms.extend(model.bond_types.iter().map(|t| ("bond", label(t), t.term())));
    terms.extend(model.angle_types.iter().map(|t| ("angle", label(t), t.term())));
    let pair_types = &model.pair_rule_types;
    terms.extend(
        model
            .pair_rules
            .iter()
            .zip(pair_types)
            .map(|(t, &(a, b))| ("pair", format!("{} {}", names[a as usize], names[b as usize]), t.term())),
    );
    terms.extend(model.body_rules.iter().map(|t| ("body", label(t), t.term())));
    terms.extend(model.contact_rules.iter().map(|t| ("contact", label(t), t.term())));
    terms.extend(model.externals.iter().map(|e| ("external", format!("{} {}", label(&e.term), e.group), e.term.term())));
    for (kind, name, term) in terms {
        let _ = write!(out, "{kind} {name} {}", term.interaction.name());
        for (spec, value) in term.interaction.params().iter().zip(&term.params) {
            let _ = write!(out, " {} {value:e} [{}]", spec.name, model.units.label(spec.dim));
        }
        out.push('\n');
    }
    for (t, name) in names.iter().enumerate() {
        let _ = writeln!(out, "particle {name} drag {:e} radius {:e}", model.type_drag[t], model.type_radius[t]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_adds_up_and_names_the_unaccounted_time() {
        let mut times = PhaseTimes::default();
        times.phases[Phase::Force as usize] = Duration::from_millis(600);
        times.phases[Phase::Output as usize] = Duration::from_millis(100);
        times.total = Duration::from_millis(1000);
        let table = times.table();
        assert!(table.contains("Force     |      0.600 |   60.0"), "{table}");
        assert!(table.contains("Output    |      0.100 |   10.0"), "{table}");
        assert!(table.contains("Other     |      0.300 |   30.0"), "{table}");
        assert!(table.contains("Total     |      1.000 |  100.0"), "{table}");
    }

    #[test]
    fn the_clock_charges_each_lap_to_its_phase() {
        let mut times = PhaseTimes::default();
        let mut clock = times.clock();
        std::thread::sleep(Duration::from_millis(20));
        clock.lap(&mut times, Phase::Neighbor);
        clock.lap(&mut times, Phase::Force);
        assert!(times.of(Phase::Neighbor) >= Duration::from_millis(20));
        assert!(times.of(Phase::Force) < Duration::from_millis(20));
    }
}
