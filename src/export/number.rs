//! Numbers in the text written for LAMMPS.

/// Shortest text that reads back as exactly `x` (LAMMPS parses it with strtod).
pub fn num(x: f64) -> String {
    format!("{x:?}")
}
