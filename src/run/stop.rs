//! Stopping a run early and cleanly: on SIGTERM or SIGINT (a Slurm time-out,
//! Ctrl-C), or when stdout is closed (`cellmd run deck.in | head`).
//!
//! A [`StopSignal`] is one atomic word. The signal handlers (installed by
//! [`StopSignal::on_signals`], through `signal-hook`) only store into it; the
//! step loop reads it once per step (on the GPU, at each synchronisation),
//! finishes the step, and the run then flushes and closes every output,
//! writes a restart and ends with [`STOPPED_STATUS`]. A second signal while
//! that is under way ends the process at once with status 128 + the signal.

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// Exit status of a run stopped early by a signal or a closed stdout, after
/// its outputs were finalised and its restart written.
pub const STOPPED_STATUS: u8 = 5;

/// The word's value for a closed stdout (signals store their number).
const STDOUT_CLOSED: usize = usize::MAX;

/// Why a run stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// SIGTERM, SIGINT (the signal's number).
    Signal(i32),
    /// Writing to stdout failed (a closed pipe).
    StdoutClosed,
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StopReason::Signal(signal_hook::consts::SIGTERM) => write!(f, "SIGTERM"),
            StopReason::Signal(signal_hook::consts::SIGINT) => write!(f, "SIGINT"),
            StopReason::Signal(n) => write!(f, "signal {n}"),
            StopReason::StdoutClosed => write!(f, "stdout was closed"),
        }
    }
}

/// A request to stop, shared by the handlers and the run loop; clones share it.
#[derive(Clone, Debug, Default)]
pub struct StopSignal(Arc<AtomicUsize>);

impl StopSignal {
    /// A signal that only [`request`](Self::request) sets (library use, tests).
    pub fn new() -> Self {
        Self::default()
    }

    /// A signal set by SIGTERM and SIGINT; a second one exits at once.
    pub fn on_signals() -> io::Result<Self> {
        let stop = Self::new();
        let seen = Arc::new(AtomicBool::new(false));
        for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
            // Registered first, so it sees the flag as the previous signal left it.
            signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, Arc::clone(&seen))?;
            signal_hook::flag::register(signal, Arc::clone(&seen))?;
            signal_hook::flag::register_usize(signal, Arc::clone(&stop.0), signal as usize)?;
        }
        Ok(stop)
    }

    pub fn request(&self, reason: StopReason) {
        let word = match reason {
            StopReason::Signal(n) => n as usize,
            StopReason::StdoutClosed => STDOUT_CLOSED,
        };
        self.0.store(word, Ordering::SeqCst);
    }

    /// Why a stop was requested, if it was.
    pub fn requested(&self) -> Option<StopReason> {
        match self.0.load(Ordering::SeqCst) {
            0 => None,
            STDOUT_CLOSED => Some(StopReason::StdoutClosed),
            n => Some(StopReason::Signal(n as i32)),
        }
    }

    /// Prints a line on stdout; when stdout is closed, requests a stop
    /// instead of failing (Rust's `println!` would panic).
    pub fn say(&self, line: &str) {
        if self.requested() == Some(StopReason::StdoutClosed) {
            return;
        }
        let mut out = io::stdout().lock();
        if writeln!(out, "{line}").and_then(|()| out.flush()).is_err() {
            self.request(StopReason::StdoutClosed);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_shared_by_clones_and_keep_their_reason() {
        let stop = StopSignal::new();
        let seen_by_loop = stop.clone();
        assert_eq!(seen_by_loop.requested(), None);
        stop.request(StopReason::Signal(signal_hook::consts::SIGTERM));
        assert_eq!(seen_by_loop.requested(), Some(StopReason::Signal(15)));
        assert_eq!(seen_by_loop.requested().unwrap().to_string(), "SIGTERM");
        stop.request(StopReason::StdoutClosed);
        assert_eq!(seen_by_loop.requested(), Some(StopReason::StdoutClosed));
    }
}
