//! Thermo output: aligned columns on stdout and a CSV file.
//!
//! Columns and their units (cell units shown; `cellmd` prints the active
//! system's units in the header):
//!
//! | column | meaning | unit |
//! |---|---|---|
//! | `step` | steps since the deck started | – |
//! | `time` | simulated time | s |
//! | `pe` | total potential energy | pN·µm |
//! | `pe/NAME` | potential energy of interaction type NAME | pN·µm |
//! | `fmax` | largest |F| on one particle | pN |
//! | `fnorm` | √(Σ|F|²) | pN |
//! | `press`, `pxx` … `pyz` | pressure tensor P = (N·kT/V)·I + W/V | Pa |
//! | `nbuild` | neighbour-list builds so far | – |

use std::fs::File;
use std::io::{BufWriter, Write};

use crate::backend::Forces;
use crate::deck::ThermoColumn;
use crate::interactions::REGISTRY;
use crate::units::{Dim, UnitSystem};

/// Values a thermo row is made from.
pub struct ThermoInputs<'a> {
    pub step: u64,
    pub time: f64,
    pub forces: &'a Forces,
    pub n_particles: usize,
    pub kt: f64,
    pub volume: f64,
    pub neighbor_builds: u64,
}

pub fn column_name(c: &ThermoColumn) -> String {
    match c {
        ThermoColumn::Step => "step".into(),
        ThermoColumn::Time => "time".into(),
        ThermoColumn::Pe => "pe".into(),
        ThermoColumn::PeOf(k) => format!("pe/{}", REGISTRY[*k].name()),
        ThermoColumn::Fmax => "fmax".into(),
        ThermoColumn::Fnorm => "fnorm".into(),
        ThermoColumn::Press => "press".into(),
        ThermoColumn::Pressure(k) => ["pxx", "pyy", "pzz", "pxy", "pxz", "pyz"][*k].into(),
        ThermoColumn::Nbuild => "nbuild".into(),
    }
}

pub fn column_unit(c: &ThermoColumn, units: UnitSystem) -> &'static str {
    match c {
        ThermoColumn::Step | ThermoColumn::Nbuild => "-",
        ThermoColumn::Time => units.label(Dim::Time),
        ThermoColumn::Pe | ThermoColumn::PeOf(_) => units.label(Dim::Energy),
        ThermoColumn::Fmax | ThermoColumn::Fnorm => units.label(Dim::Force),
        ThermoColumn::Press | ThermoColumn::Pressure(_) => units.label(Dim::Pressure),
    }
}

/// A column's value; integers are returned as exact f64.
pub fn column_value(c: &ThermoColumn, t: &ThermoInputs) -> f64 {
    let ideal = t.n_particles as f64 * t.kt / t.volume;
    let w = &t.forces.virial;
    match c {
        ThermoColumn::Step => t.step as f64,
        ThermoColumn::Time => t.time,
        ThermoColumn::Pe => t.forces.total_energy(),
        ThermoColumn::PeOf(k) => t.forces.energy_by_interaction[*k],
        ThermoColumn::Fmax => t.forces.max_force().0,
        ThermoColumn::Fnorm => t.forces.forces.iter().map(|f| f.length_squared()).sum::<f64>().sqrt(),
        ThermoColumn::Press => ideal + (w[0] + w[1] + w[2]) / (3.0 * t.volume),
        ThermoColumn::Pressure(k) => (if *k < 3 { ideal } else { 0.0 }) + w[*k] / t.volume,
        ThermoColumn::Nbuild => t.neighbor_builds as f64,
    }
}

fn is_integer(c: &ThermoColumn) -> bool {
    matches!(c, ThermoColumn::Step | ThermoColumn::Nbuild)
}

/// Thermo state of a running deck.
pub struct Thermo {
    pub every: u64,
    pub columns: Vec<ThermoColumn>,
    pub units: UnitSystem,
    file: Option<BufWriter<File>>,
    file_header_written: bool,
}

/// Minimum column width on stdout; longer names widen their column.
const WIDTH: usize = 14;

fn width(c: &ThermoColumn) -> usize {
    WIDTH.max(column_name(c).chars().count() + 2)
}

impl Thermo {
    pub fn new(units: UnitSystem) -> Self {
        Self {
            every: 0,
            columns: vec![ThermoColumn::Step, ThermoColumn::Time, ThermoColumn::Pe, ThermoColumn::Fmax, ThermoColumn::Press],
            units,
            file: None,
            file_header_written: false,
        }
    }

    pub fn set_file(&mut self, file: File) -> std::io::Result<()> {
        self.close()?;
        self.file = Some(BufWriter::new(file));
        self.file_header_written = false;
        Ok(())
    }

    /// The two header lines (names, then units) for stdout.
    pub fn header(&self) -> String {
        let names: String = self.columns.iter().map(|c| format!("{:>w$}", column_name(c), w = width(c))).collect();
        let units: String =
            self.columns.iter().map(|c| format!("{:>w$}", format!("[{}]", column_unit(c, self.units)), w = width(c))).collect();
        format!("{names}\n{units}")
    }

    /// A row for stdout; also appended to the CSV file when one is set.
    pub fn row(&mut self, inputs: &ThermoInputs) -> std::io::Result<String> {
        let values: Vec<f64> = self.columns.iter().map(|c| column_value(c, inputs)).collect();
        let line: String = self
            .columns
            .iter()
            .zip(&values)
            .map(|(c, v)| if is_integer(c) { format!("{:>w$}", *v as u64, w = width(c)) } else { format!("{:>w$.6e}", v, w = width(c)) })
            .collect();
        if let Some(file) = &mut self.file {
            if !self.file_header_written {
                let header: Vec<String> =
                    self.columns.iter().map(|c| format!("{}[{}]", column_name(c), column_unit(c, self.units))).collect();
                writeln!(file, "{}", header.join(","))?;
                self.file_header_written = true;
            }
            let fields: Vec<String> = self
                .columns
                .iter()
                .zip(&values)
                .map(|(c, v)| if is_integer(c) { format!("{}", *v as u64) } else { format!("{v:e}") })
                .collect();
            writeln!(file, "{}", fields.join(","))?;
        }
        Ok(line)
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        if let Some(f) = &mut self.file {
            f.flush()?;
        }
        Ok(())
    }

    pub fn close(&mut self) -> std::io::Result<()> {
        self.flush()?;
        self.file = None;
        Ok(())
    }
}
