//! Errors during a run, with the diagnosis a user needs to find the cause.

use std::fmt;

use crate::backend::ForceBreakdown;

/// A run that stopped.
#[derive(Debug)]
pub enum RunError {
    /// Non-finite force or position, or a displacement beyond the bound.
    Blowup {
        step: u64,
        particle_id: u64,
        what: String,
        /// The entry contributing the largest force on the particle, if any.
        culprit: Option<Box<ForceBreakdown>>,
        /// Where the last good frame was written.
        last_good: Vec<String>,
    },
    /// An output file could not be created or written (its path and the
    /// step are in the message).
    Io(String),
    /// Anything else (e.g. a box too small for the neighbour cutoff).
    Setup(String),
    /// Stopped early on request (a signal, a closed stdout), outputs
    /// finalised and a restart written.
    Stopped { step: u64, reason: String, restart: String },
}

impl RunError {
    /// The exit status of `cellmd run` ending with this error: 3 for a
    /// blow-up or another failure of the run, [`OUTPUT_ERROR_STATUS`] for an
    /// output error, [`STOPPED_STATUS`](super::stop::STOPPED_STATUS) when stopped.
    pub fn exit_status(&self) -> u8 {
        match self {
            RunError::Blowup { .. } | RunError::Setup(_) => 3,
            RunError::Io(_) => OUTPUT_ERROR_STATUS,
            RunError::Stopped { .. } => super::stop::STOPPED_STATUS,
        }
    }
}

/// Exit status of a run that could not create or write an output file.
pub const OUTPUT_ERROR_STATUS: u8 = 6;

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Blowup { step, particle_id, what, culprit, last_good } => {
                write!(f, "simulation blew up at step {step}: particle {particle_id}: {what}")?;
                match culprit {
                    Some(c) => {
                        write!(f, "; largest force on it from {} `{}` ({}), |F| = {:e}", c.kind, c.label, c.interaction, c.force.length())?
                    }
                    None => write!(f, "; no interaction acts on it (check the timestep, drag and temperature)")?,
                }
                if !last_good.is_empty() {
                    write!(f, "; last good frame written to {}", last_good.join(", "))?;
                }
                Ok(())
            }
            RunError::Io(e) => write!(f, "output error: {e}"),
            RunError::Setup(e) => write!(f, "{e}"),
            RunError::Stopped { step, reason, restart } => {
                write!(f, "stopped after step {step} ({reason}); outputs closed, restart written to {restart}")
            }
        }
    }
}

impl std::error::Error for RunError {}

/// The entry with the largest (or a non-finite) force among `parts`.
pub fn culprit(parts: Vec<ForceBreakdown>) -> Option<Box<ForceBreakdown>> {
    let key = |p: &ForceBreakdown| if p.force.is_finite() { p.force.length() } else { f64::INFINITY };
    parts
        .into_iter()
        .fold(None, |best: Option<ForceBreakdown>, p| match &best {
            Some(b) if key(b) >= key(&p) => best,
            _ => Some(p),
        })
        .map(Box::new)
}
