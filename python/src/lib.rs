//! `cellmd._native`: the Python module behind the `cellmd` package.
//!
//! A [`PySimulation`] is a deck kept open ([`cellmd::deck::OpenDeck`]) and
//! the live [`cellmd::run::Simulation`] it set up: the deck's own commands
//! run up to its first `run` or `minimize` when it is loaded, later ones on
//! request, and Python issues further deck commands, runs in segments with a
//! callback between them ([`cellmd::run::ActiveRun`]) and reads the state as
//! numpy arrays. Input errors become `cellmd.InputError` (a `ValueError`
//! whose text is the `file:line:col: found …, expected …` message, with
//! `path`, `line`, `col` and `message` attributes); run errors (blow-ups,
//! output failures) become `cellmd.RunError` (a `RuntimeError`).
//! Docstrings here are what `help()` shows; `cellmd/_native.pyi` gives the types.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use glam::DVec3;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};

use cellmd::deck::{Action, OpenDeck};
use cellmd::gpu::DevicePreference;
use cellmd::input::SourceFile;
use cellmd::run::{RunError as CoreRunError, RunOptions, Simulation};

pyo3::create_exception!(
    cellmd,
    InputError,
    PyValueError,
    "A bad deck, topology, force field or command: `file:line:col: found …, expected …` (attributes path, line, col, message)."
);
pyo3::create_exception!(
    cellmd,
    RunError,
    PyRuntimeError,
    "A run that stopped: a blow-up (with its diagnosis), an output error or a setup the backend refuses."
);

/// The `InputError` of a cellmd input error, with its position as attributes.
fn input_error(py: Python<'_>, e: cellmd::input::InputError) -> PyErr {
    let err = InputError::new_err(e.to_string());
    let value = err.value(py);
    let _ = value.setattr("path", &e.path);
    let _ = value.setattr("line", e.line);
    let _ = value.setattr("col", e.col);
    let _ = value.setattr("message", &e.message);
    err
}

fn run_error(e: CoreRunError) -> PyErr {
    RunError::new_err(e.to_string())
}

/// An N×3 array of vectors.
fn vectors<'py>(py: Python<'py>, v: &[DVec3]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = v.iter().flat_map(|x| x.to_array()).collect();
    Array2::from_shape_vec((v.len(), 3), flat).expect("n×3").into_pyarray(py)
}

/// A live simulation set up by a deck (see the module docs and `cellmd.Simulation`).
// Unsendable: output writers are Send but not Sync; a simulation stays on the thread that made it.
#[pyclass(module = "cellmd._native", name = "Simulation", subclass, unsendable)]
pub struct PySimulation {
    sim: Simulation,
    deck: OpenDeck,
    /// The deck's actions not yet applied (from its first `run` or `minimize` on).
    pending: VecDeque<Action>,
    /// Worker threads of this simulation (None: rayon's global pool).
    pool: Option<rayon::ThreadPool>,
    /// Set while a `run` with a callback is between segments.
    running: bool,
    /// Commands issued so far (each text is named `<command N>` in errors).
    commands: usize,
}

impl PySimulation {
    /// Runs `f` on this simulation's threads.
    fn on_threads<R: Send>(&mut self, f: impl FnOnce(&mut Simulation) -> R + Send) -> R {
        match &self.pool {
            Some(pool) => pool.install(|| f(&mut self.sim)),
            None => f(&mut self.sim),
        }
    }

    fn not_running(&self, what: &str) -> PyResult<()> {
        if self.running {
            return Err(PyRuntimeError::new_err(format!("{what} inside a run's callback; expected it after the run returns")));
        }
        Ok(())
    }

    fn apply_all(&mut self, actions: impl IntoIterator<Item = Action>) -> PyResult<()> {
        for action in actions {
            self.on_threads(|sim| sim.apply(&action)).map_err(run_error)?;
        }
        Ok(())
    }

    /// Validates `text` as deck lines named `<command N>`.
    fn validate(&mut self, py: Python<'_>, text: &str) -> PyResult<Vec<Action>> {
        self.commands += 1;
        let file = SourceFile::new(format!("<command {}>", self.commands), text);
        self.deck.commands(&file).map_err(|e| input_error(py, e))
    }
}

#[pymethods]
impl PySimulation {
    /// Loads a deck: validates it (with `vars` overriding its `variable`
    /// lines, as `cellmd run --var`), then applies its commands up to its
    /// first `run` or `minimize`; `run_deck()` applies the rest.
    /// Relative output paths go to `output_dir`; `device` ("cpu", "gpu" or
    /// "auto") overrides the deck's; `threads` sets this simulation's worker
    /// threads (results are identical for any count); `echo` prints thermo
    /// rows and messages to stdout as `cellmd run` does.
    #[new]
    #[pyo3(signature = (deck, vars=None, output_dir=None, device=None, threads=None, echo=false))]
    fn new(
        py: Python<'_>,
        deck: PathBuf,
        vars: Option<&Bound<'_, PyDict>>,
        output_dir: Option<PathBuf>,
        device: Option<&str>,
        threads: Option<usize>,
        echo: bool,
    ) -> PyResult<Self> {
        let mut overrides = Vec::new();
        if let Some(vars) = vars {
            for (k, v) in vars.iter() {
                overrides.push((k.str()?.to_string(), v.str()?.to_string()));
            }
        }
        let device = match device {
            None => None,
            Some(d) => Some(
                DevicePreference::from_keyword(d)
                    .ok_or_else(|| PyValueError::new_err(format!("found device `{d}`, expected cpu, gpu or auto")))?,
            ),
        };
        let pool = match threads {
            None => None,
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| PyValueError::new_err(format!("cannot start {n} threads: {e}")))?,
            ),
        };
        let (open, plan) = OpenDeck::open_file(&deck, &overrides).map_err(|e| input_error(py, e))?;
        let output_dir = output_dir.unwrap_or_else(|| PathBuf::from("."));
        std::fs::create_dir_all(&output_dir)
            .map_err(|e| RunError::new_err(format!("cannot create output directory {}: {e}", output_dir.display())))?;
        let options = RunOptions { output_dir, progress: false, echo, device, ..Default::default() };
        let mut pending: VecDeque<Action> = plan.actions.iter().cloned().collect();
        let sim = Simulation::new(&plan, options);
        drop(plan);
        let mut this = PySimulation { sim, deck: open, pending: VecDeque::new(), pool, running: false, commands: 0 };
        this.sim.record_thermo();
        let first_run = pending.iter().position(|a| matches!(a, Action::Run(_) | Action::Minimize(_))).unwrap_or(pending.len());
        let setup: Vec<Action> = pending.drain(..first_run).collect();
        this.pending = pending;
        this.apply_all(setup)?;
        Ok(this)
    }

    /// Applies the deck's remaining commands (its runs and minimisations and
    /// what follows them), as `cellmd run` would.
    fn run_deck(&mut self) -> PyResult<()> {
        self.not_running("run_deck()")?;
        let rest: Vec<Action> = self.pending.drain(..).collect();
        self.apply_all(rest)
    }

    /// The number of the deck's commands not yet applied.
    #[getter]
    fn pending_commands(&self) -> usize {
        self.pending.len()
    }

    /// Executes deck lines (one or several, `\n`-separated) against the
    /// live system, validated in the deck's context: `coeff`, `external`,
    /// `temperature`, `thermo`, `dump`, `group`, `displace_atoms`,
    /// `write_state`, `run`, … An error names the text `<command N>` and
    /// its line and column; a text with an error applies none of its lines.
    /// Inside a run's callback every command but `run` and `minimize` may
    /// be given (the next steps use the changed system).
    fn command(&mut self, py: Python<'_>, text: &str) -> PyResult<()> {
        let actions = self.validate(py, text)?;
        if actions.iter().any(|a| matches!(a, Action::Run(_) | Action::Minimize(_))) {
            self.not_running("`run` or `minimize`")?;
        }
        self.apply_all(actions)
    }

    /// Runs `steps` steps. With `callback` and `every`, calls
    /// `callback(sim)` at every step that is a multiple of `every` (as thermo
    /// rows are) and at the run's end; the callback may read the system or
    /// change it (`command()` but for `run`/`minimize`, `positions`), and
    /// returning False ends the run early. The steps are the same, bit for
    /// bit, with or without a callback (on the CPU).
    #[pyo3(signature = (steps, callback=None, every=None))]
    fn run(slf: &Bound<'_, Self>, steps: u64, callback: Option<Bound<'_, PyAny>>, every: Option<u64>) -> PyResult<()> {
        let py = slf.py();
        let every = match (&callback, every) {
            (Some(_), Some(0)) | (Some(_), None) => {
                return Err(PyValueError::new_err("a callback needs `every` > 0 (steps between calls)"))
            }
            (None, Some(_)) => return Err(PyValueError::new_err("`every` without a callback; expected both or neither")),
            (_, every) => every,
        };
        let run = {
            let mut this = slf.borrow_mut();
            this.not_running("run()")?;
            this.validate(py, &format!("run {steps}"))?;
            this.on_threads(|sim| sim.begin_run(steps)).map_err(run_error)?
        };
        let last = run.last();
        let mut outcome: PyResult<()> = Ok(());
        loop {
            let step = slf.borrow().sim.state.step;
            if step >= last {
                break;
            }
            let until = every.map_or(last, |e| (step / e + 1) * e).min(last);
            let advanced = {
                let mut this = slf.borrow_mut();
                this.on_threads(|sim| sim.advance(&run, until))
            };
            if let Err(e) = advanced {
                outcome = Err(run_error(e));
                break;
            }
            if let Some(callback) = &callback {
                slf.borrow_mut().running = true;
                let answer = callback.call1((slf,));
                slf.borrow_mut().running = false;
                let stop = answer.and_then(|v| Ok(v.is_instance_of::<PyBool>() && !v.extract::<bool>()?));
                match stop {
                    Ok(false) => {}
                    Ok(true) => break,
                    Err(e) => {
                        outcome = Err(e);
                        break;
                    }
                }
            }
            if let Err(e) = py.check_signals() {
                outcome = Err(e);
                break;
            }
        }
        let ended = slf.borrow_mut().on_threads(|sim| sim.end_run(run)).map_err(run_error);
        outcome.and(ended)
    }

    /// Energy minimisation (the deck's `minimize [ftol F] [maxiter N] [dmax D]
    /// [style fire|newton]`: FIRE, or damped Newton steps); the step counter
    /// does not advance.
    #[pyo3(signature = (ftol=None, maxiter=None, dmax=None, style=None))]
    fn minimize(
        &mut self,
        py: Python<'_>,
        ftol: Option<f64>,
        maxiter: Option<u64>,
        dmax: Option<f64>,
        style: Option<String>,
    ) -> PyResult<()> {
        self.not_running("minimize()")?;
        let mut line = String::from("minimize");
        for (key, value) in [
            ("ftol", ftol.map(|v| format!("{v:e}"))),
            ("maxiter", maxiter.map(|v| v.to_string())),
            ("dmax", dmax.map(|v| format!("{v:e}"))),
            ("style", style),
        ] {
            if let Some(value) = value {
                line.push_str(&format!(" {key} {value}"));
            }
        }
        let actions = self.validate(py, &line)?;
        self.apply_all(actions)
    }

    /// Whether the last minimisation converged (None before any).
    #[getter]
    fn minimize_converged(&self) -> Option<bool> {
        self.sim.reports.last_minimize.as_ref().map(|r| r.converged)
    }

    /// Steps taken since the deck started.
    #[getter]
    fn step(&self) -> u64 {
        self.sim.state.step
    }

    /// Simulated time (time units).
    #[getter]
    fn time(&self) -> f64 {
        self.sim.state.time
    }

    /// Particle ids of the topology, in internal order (the row order of every per-particle array).
    #[getter]
    fn ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        self.sim.model.ids.clone().into_pyarray(py)
    }

    /// Particle type index of each particle (into `type_names`).
    #[getter]
    fn types<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.sim.model.types.clone().into_pyarray(py)
    }

    #[getter]
    fn type_names(&self) -> Vec<String> {
        self.sim.model.type_names.clone()
    }

    /// Positions (N×3, wrapped into the box). Setting them moves every
    /// particle (wrapped on periodic axes, image counters kept).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors(py, &self.sim.state.positions)
    }

    #[setter]
    fn set_positions(&mut self, positions: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let a = positions.as_array();
        if a.ncols() != 3 {
            return Err(PyValueError::new_err(format!("found positions of shape {:?}, expected (N, 3)", a.shape())));
        }
        let new: Vec<DVec3> = a.rows().into_iter().map(|r| DVec3::new(r[0], r[1], r[2])).collect();
        self.on_threads(|sim| sim.set_positions(&new)).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Periodic image counters (N×3); unwrapped = positions + images·box lengths.
    #[getter]
    fn images<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        let flat: Vec<i64> = self.sim.state.images.iter().flatten().copied().collect();
        Array2::from_shape_vec((self.sim.state.images.len(), 3), flat).expect("n×3").into_pyarray(py)
    }

    /// Unwrapped positions (N×3).
    #[getter]
    fn unwrapped_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let s = &self.sim;
        let unwrapped: Vec<DVec3> = s.state.positions.iter().zip(&s.state.images).map(|(&x, &n)| s.sim_box.unwrap(x, n)).collect();
        vectors(py, &unwrapped)
    }

    /// Forces on every particle at the current positions (N×3, computed now if stale).
    #[getter]
    fn forces<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let forces = self.on_threads(|sim| sim.current_forces().map(|f| f.forces.clone())).map_err(run_error)?;
        Ok(vectors(py, &forces))
    }

    /// Bonds as pairs of particle rows (M×2, indices into the per-particle arrays).
    #[getter]
    fn bonds<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        let flat: Vec<u32> = self.sim.model.bonds.iter().flatten().copied().collect();
        Array2::from_shape_vec((self.sim.model.bonds.len(), 2), flat).expect("m×2").into_pyarray(py)
    }

    /// Bond type index of each bond (into `bond_type_names`).
    #[getter]
    fn bond_types<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.sim.model.bond_type.clone().into_pyarray(py)
    }

    #[getter]
    fn bond_type_names(&self) -> Vec<String> {
        self.sim.model.bond_types.iter().map(|t| t.label.text.clone()).collect()
    }

    /// Per-bond state at the current positions, each an array over the
    /// bonds: `bound` (bool), `tension` (dE/dr, positive when stretched),
    /// `length` and `rest_length` (a bond's own r0, else its type's; NaN
    /// for laws without one).
    fn bond_state<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let table = self.on_threads(|sim| sim.bond_table()).map_err(run_error)?;
        let out = PyDict::new(py);
        out.set_item("bound", table.bound.into_pyarray(py))?;
        out.set_item("tension", table.tension.into_pyarray(py))?;
        out.set_item("length", table.length.into_pyarray(py))?;
        out.set_item("rest_length", table.rest_length.into_pyarray(py))?;
        Ok(out)
    }

    /// Per-body measures at the current positions, each an array over the
    /// bodies in `[ bodies ]` order: `id`, `type` (index into
    /// `body_type_names`), `volume` and `area`.
    fn body_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let bodies = &self.sim.model.bodies;
        let (volume, area): (Vec<f64>, Vec<f64>) = self.sim.body_volumes_and_areas().into_iter().unzip();
        let out = PyDict::new(py);
        out.set_item("id", bodies.iter().map(|b| b.id).collect::<Vec<_>>().into_pyarray(py))?;
        out.set_item("type", bodies.iter().map(|b| b.body_type).collect::<Vec<_>>().into_pyarray(py))?;
        out.set_item("volume", volume.into_pyarray(py))?;
        out.set_item("area", area.into_pyarray(py))?;
        Ok(out)
    }

    #[getter]
    fn body_type_names(&self) -> Vec<String> {
        self.sim.model.body_type_names.clone()
    }

    /// The thermo rows printed so far (since loading, or since the deck's
    /// or a command's `thermo` last changed the columns) as a dict from
    /// column label (`step`, `pe`, `volume/cell`, …) to an array over rows.
    fn thermo<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (labels, rows) = self.sim.thermo_log();
        let out = PyDict::new(py);
        for (k, label) in labels.iter().enumerate() {
            out.set_item(label, rows.iter().map(|r| r[k]).collect::<Vec<f64>>().into_pyarray(py))?;
        }
        Ok(out)
    }

    /// The value of one thermo column at the current state (any column a
    /// `thermo` line accepts, e.g. `pe`, `press`, `volume/cell`, `nbound/link`).
    fn thermo_value(&mut self, py: Python<'_>, column: &str) -> PyResult<f64> {
        self.commands += 1;
        let file = SourceFile::new(format!("<column {}>", self.commands), column);
        let column = self.deck.thermo_column(&file).map_err(|e| input_error(py, e))?;
        self.on_threads(|sim| sim.thermo_value(&column)).map_err(run_error)
    }

    /// Finishes every output file (dumps, thermo file, event log); also
    /// done when the simulation is garbage-collected or leaves a `with` block.
    fn close(&mut self) -> PyResult<()> {
        self.sim.close_outputs().map_err(run_error)
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&mut self, _args: &Bound<'_, pyo3::types::PyTuple>) -> PyResult<bool> {
        self.close()?;
        Ok(false)
    }
}

impl Drop for PySimulation {
    fn drop(&mut self) {
        let _ = self.sim.close_outputs();
    }
}

/// `cellmd build GENERATOR …` as arguments (without `cellmd build`).
#[derive(Parser)]
#[command(name = "cellmd build", no_binary_name = true)]
struct BuildCommand {
    #[command(subcommand)]
    what: cellmd::build::Generator,
}

/// Runs a topology generator with `cellmd build`'s arguments (without
/// `cellmd build`; `--output` is required by the parser but not written);
/// returns (topology text, summary, counts).
#[pyfunction]
fn build_topology(py: Python<'_>, args: Vec<String>) -> PyResult<(String, String, Py<PyDict>)> {
    let command = BuildCommand::try_parse_from(&args).map_err(|e| PyValueError::new_err(e.render().to_string()))?;
    let built = command.what.build().map_err(PyValueError::new_err)?;
    let counts = PyDict::new(py);
    for (key, n) in [
        ("particles", built.particles),
        ("bonds", built.bonds),
        ("angles", built.angles),
        ("bodies", built.bodies),
        ("triangles", built.triangles),
    ] {
        counts.set_item(key, n)?;
    }
    Ok((built.text.clone(), built.summary(), counts.unbind()))
}

/// The `cellmd` command line (`args[0]` is the program name); returns its
/// exit status. (`--help`, `--version` and bad arguments exit the process
/// from clap, as the executable does.)
#[pyfunction]
fn cli_main(args: Vec<String>) -> u8 {
    let code: ExitCode = cellmd::cli::main(args);
    let _ = std::io::Write::flush(&mut std::io::stdout());
    // ExitCode keeps its status private; it compares equal to its own u8.
    (0..=u8::MAX).find(|&c| ExitCode::from(c) == code).unwrap_or(1)
}

/// The crate version of the engine.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySimulation>()?;
    m.add_function(wrap_pyfunction!(build_topology, m)?)?;
    m.add_function(wrap_pyfunction!(cli_main, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("RunError", m.py().get_type::<RunError>())?;
    Ok(())
}
