//! The `cellmd` command line: run | check | list | docs | export-lammps |
//! compare | build | profile-gpu. The `cellmd` binary (src/main.rs) and the Python
//! package's `cellmd` console script both call [`main`].

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::compare::{golden, Lmp, Tolerance};
use crate::deck::{validate_file_with, Plan, ValidateOptions};
use crate::export::{self, ExportOptions};
use crate::gpu::{DevicePreference, GpuBackend, GpuContext};
use crate::input::replaying;
use crate::interactions::{documentation, lookup, REGISTRY};
use crate::kinetics::{lookup_rule, RULES};
use crate::output::read_state;
use crate::output::run_log::LogHeader;
use crate::run::{RunOptions, Simulation, StopReason, StopSignal, OUTPUT_ERROR_STATUS};
use crate::units::UnitSystem;

#[derive(Parser)]
#[command(name = "cellmd", version, about = "Overdamped molecular dynamics whose force fields are cell mechanics")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate and run a deck, or continue a stopped run from its restart.
    ///
    /// Exit status: 0 done; 1 bad input; 2 bad options; 3 the run failed
    /// (blow-up); 5 stopped by SIGTERM/SIGINT or a closed stdout, outputs
    /// finalised and a restart written; 6 an output file could not be written.
    Run {
        #[arg(required_unless_present = "resume")]
        deck: Option<PathBuf>,
        /// Continue the run a restart file comes from (it carries the deck,
        /// topology and force fields as read): no deck needed.
        #[arg(long = "continue", value_name = "RESTART", conflicts_with_all = ["deck", "vars"])]
        resume: Option<PathBuf>,
        /// Directory for output files (default: the working directory).
        #[arg(short, long, default_value = ".")]
        output_dir: PathBuf,
        /// Accept output paths outside the output directory (absolute or with `..`).
        #[arg(long)]
        allow_outside: bool,
        /// Set a deck variable, overriding the deck's own definition (repeatable).
        #[arg(long = "var", value_name = "NAME=VALUE", value_parser = parse_var)]
        vars: Vec<(String, String)>,
        /// Worker threads (default: all cores). Results are identical for any count.
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Backend for the steps, overriding the deck's `device`: cpu, gpu or auto.
        #[arg(long, value_parser = parse_device)]
        device: Option<DevicePreference>,
    },
    /// Time each phase of a GPU step on a deck's initial system (neighbour
    /// check, rebuild, forces, integration, read-back) and print the shares.
    ProfileGpu {
        deck: PathBuf,
        #[arg(long = "var", value_name = "NAME=VALUE", value_parser = parse_var)]
        vars: Vec<(String, String)>,
        /// Calls of each phase to average over.
        #[arg(long, default_value_t = 20)]
        repetitions: u32,
        /// Neighbour-list rebuilds per step to weight the rebuild cost by
        /// (default: from 200 GPU steps of the deck).
        #[arg(long)]
        rebuild_rate: Option<f64>,
    },
    /// Validate a deck (and its topology and force fields) without running it.
    Check {
        deck: PathBuf,
        #[arg(long = "var", value_name = "NAME=VALUE", value_parser = parse_var)]
        vars: Vec<(String, String)>,
        /// Accept output paths outside the output directory (absolute or with `..`).
        #[arg(long)]
        allow_outside: bool,
        /// Also run the shared physics checks (F = −∇E, Σf = 0, rigid-motion
        /// invariance) on every `custom` term of the deck.
        #[arg(long)]
        selftest: bool,
    },
    /// Write a LAMMPS data file and input script equivalent to the deck.
    ExportLammps {
        deck: PathBuf,
        /// Directory for `data.lammps` and `in.lammps`.
        outdir: PathBuf,
        #[arg(long = "var", value_name = "NAME=VALUE", value_parser = parse_var)]
        vars: Vec<(String, String)>,
        /// Also write the probe files `cellmd compare` reads.
        #[arg(long)]
        probes: bool,
    },
    /// Translate a LAMMPS data file (and the input script that reads it) into
    /// DIR/system.top, system.ff and system.in, listing what it could not
    /// translate. An input script alone names its data file by `read_data`.
    ImportLammps {
        /// The data file, or the input script (whose `read_data` names the data file).
        data: PathBuf,
        input: Option<PathBuf>,
        #[arg(short, long, value_name = "DIR")]
        output: PathBuf,
    },
    /// Run the deck in cellmd and in LAMMPS and compare energies, forces and positions.
    Compare {
        deck: PathBuf,
        #[arg(long = "var", value_name = "NAME=VALUE", value_parser = parse_var)]
        vars: Vec<(String, String)>,
        /// The lmp executable (default: $CELLMD_LMP, lmp on PATH, or scripts/reference-venv --lmp).
        #[arg(long)]
        lmp: Option<PathBuf>,
        /// Keep LAMMPS' files in this directory (default: a temporary one).
        #[arg(long)]
        workdir: Option<PathBuf>,
        /// Tolerance of energies, forces and virial at one configuration (relative).
        #[arg(long, default_value_t = 1e-10)]
        tol: f64,
        /// Tolerance of positions, forces and energies after the run (relative).
        #[arg(long, default_value_t = 1e-9)]
        run_tol: f64,
        /// Also write LAMMPS' results as a golden document (reference/*.yaml) to this file.
        #[arg(long, value_name = "FILE")]
        write_golden: Option<PathBuf>,
        /// `key=value` header entries of the golden document (repeatable).
        #[arg(long = "golden-header", value_name = "KEY=VALUE", value_parser = parse_var)]
        golden_header: Vec<(String, String)>,
    },
    /// Write a topology file of a generated system (deterministic).
    Build {
        // Boxed: the generators' options dwarf every other command's.
        #[command(subcommand)]
        what: Box<crate::build::Generator>,
    },
    /// Write the manual's generated pages (one per interaction type, kinetic
    /// rule, deck command and example deck) into the mdBook's source, or
    /// with `--check` list those that are missing, stale or left over.
    Docs {
        /// The book's source folder (its SUMMARY.md has the generated sections' markers).
        #[arg(long, default_value = "docs/src")]
        book: PathBuf,
        /// The example decks shown in the gallery.
        #[arg(long, default_value = "inputs")]
        inputs: PathBuf,
        /// Write nothing: exit with status 1 if any generated page differs.
        #[arg(long)]
        check: bool,
    },
    /// List interaction types and kinetic rules, or print one's documentation.
    List {
        name: Option<String>,
        /// Show units of the `lj` system instead of `cell`.
        #[arg(long)]
        lj: bool,
    },
}

fn parse_device(s: &str) -> Result<DevicePreference, String> {
    DevicePreference::from_keyword(s).ok_or_else(|| format!("found `{s}`, expected cpu, gpu or auto"))
}

fn parse_var(s: &str) -> Result<(String, String), String> {
    s.split_once('=').map(|(a, b)| (a.to_string(), b.to_string())).ok_or_else(|| format!("expected NAME=VALUE, found `{s}`"))
}

/// Prints a line on stdout like `println!`, which would panic when the
/// reader has gone (`cellmd list | head -3`). A closed pipe only stops the
/// printing: the command goes on to its own exit status (a `compare` that
/// disagrees still exits 4). Any other write error (a full disk behind a
/// redirection) names itself and returns exit status 6 from the caller.
macro_rules! out {
    ($($arg:tt)*) => {
        if let Err(code) = emit(format_args!($($arg)*)) {
            return code;
        }
    };
}

/// Writes one line for [`out!`]: `Err` carries the exit status when stdout
/// failed for a reason other than a departed reader.
fn emit(line: std::fmt::Arguments) -> Result<(), ExitCode> {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_fmt(line).and_then(|()| stdout.write_all(b"\n")).and_then(|()| stdout.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            eprintln!("error: cannot write to stdout: {e}");
            Err(ExitCode::from(OUTPUT_ERROR_STATUS))
        }
        _ => Ok(()),
    }
}

fn report(error: impl miette::Diagnostic + Send + Sync + 'static) -> ExitCode {
    eprintln!("{:?}", miette::Report::new(error));
    ExitCode::from(1)
}

/// Runs the command line `args` (the program name first, as
/// [`std::env::args_os`] gives it) and returns the process's exit status.
/// `--help`, `--version` and malformed arguments print clap's text and exit
/// the process, as a command line does.
pub fn main<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    // One unwrapped `file:line:col: message` line, then the source snippet.
    let _ = miette::set_hook(Box::new(|_| Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())));
    let cli = Cli::parse_from(args);
    match cli.command {
        Command::Build { what } => build(what),
        Command::Docs { book, inputs, check } => docs(&book, &inputs, check),
        Command::List { name, lj } => {
            let units = if lj { UnitSystem::Lj } else { UnitSystem::Cell };
            match name {
                None => {
                    out!("{:<16} {:<9} summary", "name", "kind");
                    for i in REGISTRY {
                        out!("{:<16} {:<9} {}", i.name(), i.kind().keyword(), i.summary());
                    }
                    for r in RULES {
                        out!("{:<16} {:<9} {}", r.name(), "kinetics", r.summary());
                    }
                }
                Some(name) => match (lookup(&name), lookup_rule(&name)) {
                    (Some(i), _) => out!("{}", documentation(i, units)),
                    (None, Some(r)) => out!("{}", documentation(r, units)),
                    (None, None) => {
                        let names: Vec<&str> = REGISTRY.iter().map(|i| i.name()).chain(RULES.iter().map(|r| r.name())).collect();
                        eprintln!("error: unknown interaction or kinetic rule `{name}`; expected one of: {}", names.join(", "));
                        return ExitCode::from(2);
                    }
                },
            }
            ExitCode::SUCCESS
        }
        Command::ProfileGpu { deck, vars, repetitions, rebuild_rate } => {
            let _runtime_dir = headless_runtime_dir();
            let plan = match validated(&deck, &vars, ValidateOptions::default()) {
                Ok(plan) => plan,
                Err(e) => return report(e),
            };
            match profile_gpu(&plan, repetitions, rebuild_rate) {
                Ok(table) => {
                    out!("{}", table.trim_end());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(3)
                }
            }
        }
        Command::Check { deck, vars, allow_outside, selftest } => match validated(&deck, &vars, ValidateOptions { allow_outside }) {
            Ok(plan) => {
                out!(
                    "{}: ok ({} particles, {} bonds, {} angles, {} actions)",
                    deck.display(),
                    plan.model.len(),
                    plan.model.bonds.len(),
                    plan.model.angles.len(),
                    plan.actions.len()
                );
                if !selftest {
                    return ExitCode::SUCCESS;
                }
                let externals: Vec<_> =
                    plan.actions.iter().filter_map(|a| if let crate::deck::Action::External(e) = a { Some(e) } else { None }).collect();
                let results = crate::system::check_custom_terms(&plan.model, &externals, &plan.positions, &plan.sim_box);
                for result in &results {
                    match result {
                        Ok(line) => out!("selftest: {line}"),
                        Err(e) => eprintln!("error: selftest: {e}"),
                    }
                }
                if results.iter().any(Result::is_err) {
                    return ExitCode::from(1);
                }
                out!("selftest: {} custom term(s) pass F = -grad E, sum f = 0 and rigid-motion checks", results.len());
                ExitCode::SUCCESS
            }
            Err(e) => report(e),
        },
        Command::ExportLammps { deck, outdir, vars, probes } => {
            let plan = match validated(&deck, &vars, ValidateOptions::default()) {
                Ok(plan) => plan,
                Err(e) => return report(e),
            };
            match export::export(&plan, ExportOptions { probes }) {
                Ok(lammps) => match export::lammps::write(&lammps, &outdir) {
                    Ok(()) => {
                        out!("wrote {0}/data.lammps and {0}/in.lammps", outdir.display());
                        ExitCode::SUCCESS
                    }
                    Err(e) => {
                        eprintln!("error: {e}");
                        ExitCode::from(OUTPUT_ERROR_STATUS)
                    }
                },
                Err(e) => {
                    eprintln!("error: cannot export {} to LAMMPS: {e}", deck.display());
                    ExitCode::from(2)
                }
            }
        }
        Command::ImportLammps { data, input, output } => match export::import_lammps::read_files(&data, input.as_deref()) {
            Ok(imported) => {
                if let Err(e) = imported.write(&output) {
                    eprintln!("error: {e}");
                    return ExitCode::from(OUTPUT_ERROR_STATUS);
                }
                out!("wrote {0}/system.top, {0}/system.ff and {0}/system.in", output.display());
                for note in &imported.notes {
                    out!("note: {note}");
                }
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
        Command::Compare { deck, vars, lmp, workdir, tol, run_tol, write_golden, golden_header } => {
            let plan = match validated(&deck, &vars, ValidateOptions::default()) {
                Ok(plan) => plan,
                Err(e) => return report(e),
            };
            match compare(&plan, lmp, workdir, Tolerance { single_point: tol, run: run_tol }, write_golden, golden_header) {
                Ok((table, agrees)) => {
                    out!("{}", table.trim_end());
                    if agrees {
                        ExitCode::SUCCESS
                    } else {
                        ExitCode::from(4)
                    }
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
            }
        }
        Command::Run { deck, resume, output_dir, allow_outside, vars, threads, quiet, device } => {
            let _runtime_dir = headless_runtime_dir();
            if let Some(n) = threads {
                if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
                    eprintln!("error: cannot start {n} threads: {e}");
                    return ExitCode::from(2);
                }
            }
            let restart = match resume.as_deref().map(read_state).transpose() {
                Ok(restart) => restart,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(1);
                }
            };
            let options = ValidateOptions { allow_outside };
            let plan = match (&restart, &deck) {
                (Some(data), _) => match &data.resume {
                    Some(r) => replaying(&r.inputs.files, || validate_file_with(Path::new(&r.inputs.deck), &r.inputs.vars, options)),
                    None => {
                        eprintln!(
                            "error: {}: this restart carries no deck (written by an older cellmd); continue it with a deck's `read_state`",
                            resume.as_ref().expect("restart read").display()
                        );
                        return ExitCode::from(1);
                    }
                },
                (None, Some(deck)) => validated(deck, &vars, options),
                (None, None) => unreachable!("clap requires a deck or --continue"),
            };
            let plan = match plan {
                Ok(plan) => plan,
                Err(e) => return report(e),
            };
            // A restart that does not fit its deck is bad input: refused before any output exists.
            if let (Some(data), Some(path)) = (&restart, &resume) {
                if let Err(e) = Simulation::check_restart(&plan, data, path) {
                    eprintln!("error: {e}");
                    return ExitCode::from(1);
                }
            }
            if let Err(e) = std::fs::create_dir_all(&output_dir) {
                eprintln!("error: cannot create output directory {}: {e}", output_dir.display());
                return ExitCode::from(OUTPUT_ERROR_STATUS);
            }
            let stop = match StopSignal::on_signals() {
                Ok(stop) => stop,
                Err(e) => {
                    eprintln!("error: cannot install the SIGTERM/SIGINT handlers: {e}");
                    return ExitCode::from(2);
                }
            };
            let interactive = std::io::stderr().is_terminal() && std::env::var_os("CI").is_none();
            let log = LogHeader {
                version: format!("cellmd {} (git {})", env!("CARGO_PKG_VERSION"), env!("CELLMD_GIT_HASH")),
                command_line: std::env::args().collect::<Vec<_>>().join(" "),
            };
            let options =
                RunOptions { output_dir, progress: interactive && !quiet, echo: true, device, stop: stop.clone(), log: Some(log) };
            stop.say(&format!(
                "cellmd {}: {} — {} particles, {} bonds, {} angles, {} pair rules; {} CPU threads",
                env!("CARGO_PKG_VERSION"),
                plan.inputs.deck,
                plan.model.len(),
                plan.model.bonds.len(),
                plan.model.angles.len(),
                plan.model.pair_rules.len(),
                rayon::current_num_threads()
            ));
            let started = std::time::Instant::now();
            // The run loop itself runs on a worker of the pool, so that each
            // parallel pass of a step starts where its work is queued instead
            // of waking a worker from this thread (a context switch per pass:
            // ~10 % of a 50-fibre step on one thread).
            let outcome = rayon::scope(|_| match (restart, resume) {
                (Some(data), Some(path)) => Simulation::resume(plan, data, &path, options),
                _ => Simulation::execute(plan, options),
            });
            match outcome {
                Ok(sim) => {
                    stop.say(&format!("done: {} steps in {:.2} s", sim.state.step, started.elapsed().as_secs_f64()));
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    // A closed stdout is an ordinary end for a pipe (`| head`): no message.
                    if stop.requested() != Some(StopReason::StdoutClosed) {
                        eprintln!("error: {e}");
                    }
                    ExitCode::from(e.exit_status())
                }
            }
        }
    }
}

/// Mesa's Vulkan loader complains ("error: XDG_RUNTIME_DIR is invalid")
/// when the variable is unset, as in batch jobs and containers: a private
/// directory (mode 0700, removed at exit) stands in for it. Called before
/// any thread starts and before the Vulkan instance exists.
/// `cellmd docs`: writes (or with `check` compares) the manual's generated pages.
fn docs(book: &Path, inputs: &Path, check: bool) -> ExitCode {
    let decks = match crate::manual::read_decks(book, inputs) {
        Ok(decks) => decks,
        Err(e) => {
            eprintln!("error: {}: {e}", inputs.display());
            return ExitCode::from(1);
        }
    };
    let manual = crate::manual::generate(&decks);
    let result = if check { crate::manual::check(book, &manual) } else { crate::manual::write(book, &manual).map(|_| Vec::new()) };
    match result {
        Ok(problems) if problems.is_empty() => {
            out!("{}: {} generated pages up to date", book.display(), manual.pages.len());
            ExitCode::SUCCESS
        }
        Ok(problems) => {
            for problem in &problems {
                eprintln!("error: {}/{problem}", book.display());
            }
            ExitCode::from(1)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}

fn headless_runtime_dir() -> Option<tempfile::TempDir> {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return None;
    }
    let dir = tempfile::Builder::new().prefix("cellmd-runtime-").tempdir().ok()?;
    std::env::set_var("XDG_RUNTIME_DIR", dir.path());
    Some(dir)
}

/// `cellmd build ...`: writes the topology and prints its summary; bad
/// options exit with status 2 and what was expected.
fn build(what: Box<crate::build::Generator>) -> ExitCode {
    let built = match what.build() {
        Ok(built) => built,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let output = what.output();
    if let Err(e) = std::fs::write(output, &built.text) {
        eprintln!("error: cannot write {}: {e}", output.display());
        return ExitCode::from(1);
    }
    out!("wrote {}: {}", output.display(), built.summary());
    ExitCode::SUCCESS
}

/// `cellmd profile-gpu`: the table of GPU phase times on the deck's initial
/// system.
fn profile_gpu(plan: &crate::deck::Plan, repetitions: u32, rebuild_rate: Option<f64>) -> Result<String, String> {
    let sim = Simulation::before_first_run(plan, RunOptions::default()).map_err(|e| e.to_string())?;
    let context = GpuContext::open(false)?;
    let settings = sim.step_settings();
    // Bond kinetics on the device where the run would decide them there.
    let kinetics = sim.model.has_kinetics() && crate::gpu::kinetics::refusal(&sim.model).is_none();
    // The implicit step and the constraints' projection where the run would have them.
    let constrained = sim.constraints.pairs(&sim.model);
    let backend = || -> Result<GpuBackend, String> {
        let mut gpu = match kinetics {
            true => GpuBackend::with_device_kinetics(&context, &sim.model, &sim.state, &sim.sim_box, &settings, &[])?,
            false => GpuBackend::new(&context, &sim.model, &sim.state, &sim.sim_box, &settings)?,
        };
        if let crate::integrate::Integrator::Implicit(_, implicit) = &sim.settings.integrator {
            gpu.step_implicitly(&context, &sim.model, &settings, implicit, &constrained)?;
        }
        if !constrained.is_empty() {
            gpu.constrain_bonds(&context, &sim.model, &sim.constraints)?;
        }
        Ok(gpu)
    };
    let mut gpu = backend()?;
    let rate = match rebuild_rate {
        Some(rate) => rate,
        None => {
            let mut probe = backend()?;
            let before = probe.neighbor_builds();
            // A step whose `bind` formation the device left to the host (src/gpu/bind.rs) ends the probe early.
            let done = match probe.run(0, 200) {
                Ok(done) | Err(crate::gpu::GpuHalt::Formation { step: done }) => done,
                Err(e) => return Err(format!("{e:?}")),
            };
            (probe.neighbor_builds() - before).saturating_sub(1) as f64 / done.max(1) as f64
        }
    };
    let t = gpu.profile(repetitions)?;
    let step = t.check + rate * t.neighbor_build + t.forces + t.integrate + t.contact + t.adhesion + t.kinetics + t.constraints;
    let n = sim.model.len() as f64;
    let mut table = String::new();
    table += &format!("device: {}\n", context.describe());
    table += &format!("{} particles; {rate:.4} neighbour rebuilds per step\n", sim.model.len());
    table += &format!("{:<26} {:>14} {:>12}\n", "phase", "µs per call", "share/step");
    let rows = [
        ("neighbour check", t.check, t.check),
        ("neighbour rebuild", t.neighbor_build, rate * t.neighbor_build),
        ("forces", t.forces, t.forces),
        ("integration / implicit", t.integrate, t.integrate),
        ("constraint projection", t.constraints, t.constraints),
        ("contact and step clamp", t.contact, t.contact),
        ("adhesion node/weight", t.adhesion, t.adhesion),
        ("bond kinetics and bind", t.kinetics, t.kinetics),
    ];
    for (name, per_call, per_step) in rows {
        table += &format!("{name:<26} {:>14.1} {:>11.1}%\n", per_call * 1e6, 100.0 * per_step / step);
    }
    table += &format!("{:<26} {:>14.1} {:>12}\n", "read-back of positions", t.readback * 1e6, "per output");
    table += &format!("GPU step: {:.1} µs = {:.3e} particle-steps/s (kernels only, no read-back)\n", step * 1e6, n / step);
    Ok(table)
}

/// `cellmd compare`: the agreement table, and whether the engines agree.
fn compare(
    plan: &crate::deck::Plan,
    lmp: Option<PathBuf>,
    workdir: Option<PathBuf>,
    tol: Tolerance,
    write_golden: Option<PathBuf>,
    header: Vec<(String, String)>,
) -> Result<(String, bool), String> {
    let lmp = match lmp {
        Some(p) => Lmp::at(p),
        None => Lmp::find()?,
    };
    let scratch = tempfile::tempdir().map_err(|e| e.to_string())?;
    let dir = workdir.unwrap_or_else(|| scratch.path().to_path_buf());
    let comparison = crate::compare::compare_deck(plan, &lmp, &dir)?;
    if let Some(path) = write_golden {
        let mut entries = vec![("generator", format!("{} via cellmd export-lammps", comparison.version))];
        entries.extend(header.iter().map(|(k, v)| (k.as_str(), v.clone())));
        let doc = golden::document_of(&entries, &comparison.reference);
        std::fs::write(&path, golden::write(&[doc])).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok((comparison.table(plan, tol), comparison.agreement.agrees(tol)))
}

/// Validates a deck and prints its warnings on stderr.
fn validated(deck: &Path, vars: &[(String, String)], options: ValidateOptions) -> Result<Plan, crate::input::InputError> {
    let plan = validate_file_with(deck, vars, options)?;
    for warning in &plan.warnings {
        eprintln!("{warning}");
    }
    Ok(plan)
}
