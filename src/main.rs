//! `cellmd` command line: run | check | list.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use cellmd::deck::validate_file;
use cellmd::interactions::{documentation, lookup, REGISTRY};
use cellmd::run::{RunOptions, Simulation};
use cellmd::units::UnitSystem;

#[derive(Parser)]
#[command(name = "cellmd", version, about = "Overdamped molecular dynamics whose force fields are cell mechanics")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate and run a deck.
    Run {
        deck: PathBuf,
        /// Directory for output files (default: the working directory).
        #[arg(short, long, default_value = ".")]
        output_dir: PathBuf,
        /// Set a deck variable, overriding the deck's own definition (repeatable).
        #[arg(long = "var", value_name = "NAME=VALUE", value_parser = parse_var)]
        vars: Vec<(String, String)>,
        /// Worker threads (default: all cores). Results are identical for any count.
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Validate a deck (and its topology and force fields) without running it.
    Check {
        deck: PathBuf,
        #[arg(long = "var", value_name = "NAME=VALUE", value_parser = parse_var)]
        vars: Vec<(String, String)>,
    },
    /// List interaction types, or print one type's documentation.
    List {
        name: Option<String>,
        /// Show units of the `lj` system instead of `cell`.
        #[arg(long)]
        lj: bool,
    },
}

fn parse_var(s: &str) -> Result<(String, String), String> {
    s.split_once('=').map(|(a, b)| (a.to_string(), b.to_string())).ok_or_else(|| format!("expected NAME=VALUE, found `{s}`"))
}

fn report(error: impl miette::Diagnostic + Send + Sync + 'static) -> ExitCode {
    eprintln!("{:?}", miette::Report::new(error));
    ExitCode::from(1)
}

fn main() -> ExitCode {
    // One unwrapped `file:line:col: message` line, then the source snippet.
    let _ = miette::set_hook(Box::new(|_| Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())));
    let cli = Cli::parse();
    match cli.command {
        Command::List { name, lj } => {
            let units = if lj { UnitSystem::Lj } else { UnitSystem::Cell };
            match name {
                None => {
                    println!("{:<16} {:<9} summary", "name", "kind");
                    for i in REGISTRY {
                        println!("{:<16} {:<9} {}", i.name(), i.kind().keyword(), i.summary());
                    }
                }
                Some(name) => match lookup(&name) {
                    Some(i) => println!("{}", documentation(i, units)),
                    None => {
                        let names: Vec<&str> = REGISTRY.iter().map(|i| i.name()).collect();
                        eprintln!("error: unknown interaction `{name}`; expected one of: {}", names.join(", "));
                        return ExitCode::from(2);
                    }
                },
            }
            ExitCode::SUCCESS
        }
        Command::Check { deck, vars } => match validate_file(&deck, &vars) {
            Ok(plan) => {
                println!(
                    "{}: ok ({} particles, {} bonds, {} angles, {} actions)",
                    deck.display(),
                    plan.model.len(),
                    plan.model.bonds.len(),
                    plan.model.angles.len(),
                    plan.actions.len()
                );
                ExitCode::SUCCESS
            }
            Err(e) => report(e),
        },
        Command::Run { deck, output_dir, vars, threads, quiet } => {
            if let Some(n) = threads {
                if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
                    eprintln!("error: cannot start {n} threads: {e}");
                    return ExitCode::from(2);
                }
            }
            let plan = match validate_file(&deck, &vars) {
                Ok(plan) => plan,
                Err(e) => return report(e),
            };
            if let Err(e) = std::fs::create_dir_all(&output_dir) {
                eprintln!("error: cannot create output directory {}: {e}", output_dir.display());
                return ExitCode::from(1);
            }
            let interactive = std::io::stderr().is_terminal() && std::env::var_os("CI").is_none();
            let options = RunOptions { output_dir, progress: interactive && !quiet, echo: true };
            println!(
                "cellmd {}: {} — {} particles, {} bonds, {} angles, {} pair rules; CPU reference backend, {} threads",
                env!("CARGO_PKG_VERSION"),
                deck.display(),
                plan.model.len(),
                plan.model.bonds.len(),
                plan.model.angles.len(),
                plan.model.pair_rules.len(),
                rayon::current_num_threads()
            );
            let started = std::time::Instant::now();
            match Simulation::execute(&plan, options) {
                Ok(sim) => {
                    println!("done: {} steps in {:.2} s", sim.state.step, started.elapsed().as_secs_f64());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(3)
                }
            }
        }
    }
}
