//! The deck's commands as a table, in the manner of LAMMPS' command-style
//! registry: each word maps to its usage and its parser, and the words a
//! deck accepts (listed by the "unknown command" error) are the table's.
//! A parser checks one command line (`s[0]` is the command's word) against
//! the system the deck defined so far and appends the plan's actions.

use super::Validator;
use crate::input::{InputError, Token};

/// Checks one command line, given its usage (`FORM | FORM …`, each quoted
/// on its own by argument-count errors).
type Parser = fn(&mut Validator, &[Token], &str) -> Result<(), InputError>;

/// How a command is handled.
#[derive(Clone, Copy)]
enum Form {
    /// Structures the deck (variables, loops, branches): handled while the
    /// deck is unrolled into commands (`deck::control`), never parsed here.
    Block,
    /// Defines the system; refused once the system was first used.
    Setup(Parser),
    /// Any other command.
    Line(Parser),
}

/// One deck command.
struct Command {
    name: &'static str,
    usage: &'static str,
    form: Form,
}

const fn block(name: &'static str, usage: &'static str) -> Command {
    Command { name, usage, form: Form::Block }
}

const fn setup(name: &'static str, usage: &'static str, parse: Parser) -> Command {
    Command { name, usage, form: Form::Setup(parse) }
}

const fn line(name: &'static str, usage: &'static str, parse: Parser) -> Command {
    Command { name, usage, form: Form::Line(parse) }
}

/// Every command, in the order the "unknown command" error lists them.
const COMMANDS: &[Command] = &[
    setup("units", "units cell|lj", Validator::units),
    block("variable", "variable NAME equal EXPRESSION | variable NAME string TEXT"),
    block("loop", "loop VAR FIRST LAST"),
    block("endloop", "endloop"),
    block("if", "if CONDITION then"),
    block("else", "else"),
    block("endif", "endif"),
    block("break", "break"),
    setup("topology", "topology FILE [offset auto|N]", Validator::topology_command),
    setup("forcefield", "forcefield FILE", Validator::forcefield),
    setup("box", "box x LO HI p|f y LO HI p|f z LO HI p|f", Validator::box_command),
    setup(
        "special_bonds",
        "special_bonds [lj] W12 W13 W14   (each from 0 = excluded to 1 = in full)",
        Validator::special_bonds,
    ),
    line("temperature", "temperature T", Validator::temperature),
    line("timestep", "timestep DT", Validator::timestep),
    line("seed", "seed N", Validator::seed),
    line("device", "device cpu|gpu|auto", Validator::device),
    line(
        "integrator",
        "integrator overdamped|implicit [noise uniform|gaussian] [max_displacement D] [theta T] [solver cg|cholesky] [tolerance T] [max_iterations N] [gpu_workgroups one|all|auto]",
        Validator::integrator,
    ),
    line("neighbor", "neighbor skin S [every N] [check yes|no]", Validator::neighbor),
    line("thermo", "thermo N [column ...]", Validator::thermo),
    line("thermo_file", "thermo_file FILE.csv", Validator::thermo_file),
    line("events", "events FILE.csv", Validator::events),
    line("lifetimes", "lifetimes FILE.csv", Validator::lifetimes),
    line("dump", "dump NAME every N mcap|xyz|lammps|bonds|dcd FILE [columns COLUMN...] [encoding protobuf|json]", Validator::dump),
    line("undump", "undump NAME", Validator::undump),
    line("group", "group NAME type T... | id N|A:B ... | all", Validator::group),
    line("external", "external NAME GROUP INTERACTION [param value]...", Validator::external),
    line("unexternal", "unexternal NAME", Validator::unexternal),
    line("displace_atoms", "displace_atoms GROUP move DX DY DZ", Validator::displace_atoms),
    line(
        "coeff",
        "coeff bond|angle NAME PARAM VALUE ... | coeff pair A B PARAM VALUE ... | coeff body TYPE LAW PARAM VALUE ... | coeff external NAME PARAM VALUE ...",
        Validator::coeff,
    ),
    line(
        "ramp",
        "ramp bond|angle NAME PARAM FROM TO | ramp pair A B PARAM FROM TO | ramp body TYPE LAW PARAM FROM TO | ramp external NAME PARAM FROM TO",
        |v, s, usage| v.protocol(s, usage, Validator::ramp),
    ),
    line("move", "move GROUP linear VX VY VZ | move GROUP velocity \"VX\" \"VY\" \"VZ\"", |v, s, usage| v.protocol(s, usage, Validator::move_group)),
    line("unmove", "unmove GROUP", |v, s, usage| v.protocol(s, usage, Validator::release)),
    line("freeze", "freeze GROUP x|y|z ...", |v, s, usage| v.protocol(s, usage, Validator::freeze)),
    line("unfreeze", "unfreeze GROUP", |v, s, usage| v.protocol(s, usage, Validator::release)),
    line("reset_rest", "reset_rest BONDTYPE|all", |v, s, usage| v.protocol(s, usage, Validator::reset_rest)),
    line("indent", "indent NAME velocity VX VY VZ [until LOAD] | indent NAME stop", |v, s, usage| {
        v.protocol(s, usage, Validator::indent)
    }),
    line("constrain", "constrain BONDTYPE [tolerance T] [max_iterations N] [method fibre|shake] [reshape yes|no]", Validator::constrain),
    line("unconstrain", "unconstrain BONDTYPE", Validator::constrain),
    line("minimize", "minimize [ftol F] [maxiter N] [dmax D] [style fire|newton]", Validator::minimize),
    line("run", "run N", Validator::run),
    line("write_state", "write_state FILE [every N [keep K]]", Validator::write_state),
    line("read_state", "read_state FILE", Validator::read_state),
    line("print", "print TEXT...", Validator::print),
];

/// The words a deck accepts, comma-separated in table order.
fn accepted() -> String {
    COMMANDS.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
}

/// One section per command (`## name`), the text of its reference page.
const DOCS: &str = include_str!("commands.md");

/// A deck command as its reference page shows it (`cellmd docs`).
pub struct CommandDoc {
    pub name: &'static str,
    /// `FORM | FORM …`, as the argument-count errors quote it.
    pub usage: &'static str,
    /// `setup` (defines the system, before its first use), `block`
    /// (structures the deck) or `command`.
    pub kind: &'static str,
    /// The command's section of `commands.md`, without its heading.
    pub doc: &'static str,
}

/// Every command, in table order, with its section of `commands.md` (empty
/// if it has none: the table's test fails then).
pub fn command_docs() -> Vec<CommandDoc> {
    COMMANDS
        .iter()
        .map(|c| {
            let kind = match c.form {
                Form::Block => "block",
                Form::Setup(_) => "setup",
                Form::Line(_) => "command",
            };
            CommandDoc { name: c.name, usage: c.usage, kind, doc: section(c.name).unwrap_or("") }
        })
        .collect()
}

/// The text under `## name` of `commands.md`, up to the next heading.
fn section(name: &str) -> Option<&'static str> {
    let heading = format!("\n## {name}\n");
    let start = DOCS.find(&heading)? + heading.len();
    let end = DOCS[start..].find("\n## ").map_or(DOCS.len(), |e| start + e);
    Some(DOCS[start..end].trim())
}

impl Validator {
    /// Checks one command line by its parser in the table.
    pub(in crate::deck) fn command(&mut self, s: &[Token]) -> Result<(), InputError> {
        let kw = &s[0];
        let found = COMMANDS.iter().find(|c| c.name == kw.text);
        match found.map(|c| (c.form, c.usage)) {
            Some((Form::Setup(parse), usage)) => {
                if self.model.is_some() {
                    return Err(kw.error(format!("`{}` changes the system after it was first used; expected it before the first group, external, coeff, run, minimize or state command", kw.text)));
                }
                parse(self, s, usage)
            }
            Some((Form::Line(parse), usage)) => parse(self, s, usage),
            // Block words never reach here: the deck's blocks consumed them.
            Some((Form::Block, _)) | None => {
                let words: Vec<&str> = s.iter().map(|t| t.text.as_str()).collect();
                let message = match super::foreign::hint(&words) {
                    Some(hint) => format!("found unknown command `{}`: {hint}; expected one of: {}", kw.text, accepted()),
                    None => format!("found unknown command `{}`, expected one of: {}", kw.text, accepted()),
                };
                Err(kw.error(message))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_word_is_listed_once_with_a_usage_that_starts_with_it() {
        let mut seen = std::collections::HashSet::new();
        for c in COMMANDS {
            assert!(seen.insert(c.name), "`{}` is in the table twice", c.name);
            assert_eq!(c.usage.split_whitespace().next(), Some(c.name), "the usage of `{}` starts with another word", c.name);
        }
        assert!(accepted().starts_with("units, variable, loop,") && accepted().ends_with("read_state, print"));
        // A hint for a word the deck accepts would never be shown.
        for word in super::super::foreign::words().chain(["fix"]) {
            assert!(!seen.contains(word), "`{word}` has a foreign-command hint but is a cellmd command");
        }
    }

    #[test]
    fn every_command_has_one_section_of_commands_md_and_no_section_is_left_over() {
        for c in COMMANDS {
            assert_eq!(DOCS.matches(&format!("\n## {}\n", c.name)).count(), 1, "commands.md needs one `## {}` section", c.name);
            assert!(!section(c.name).unwrap().is_empty(), "the `## {}` section of commands.md is empty", c.name);
        }
        let headings = DOCS.lines().filter(|l| l.starts_with("## ")).count();
        assert_eq!(headings, COMMANDS.len(), "commands.md has sections for words that are not commands");
    }
}
