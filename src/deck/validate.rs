//! Second phase of deck parsing: command-by-command validation into a [`Plan`].

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;

use super::control::{blocks, ControlState};
use super::expression::DeckExpr;
use super::placement::check_placement;
use super::plan::{Action, Group, Plan};
use super::variables::Variables;
use crate::forcefield::ForceField;
use crate::input::{lex, parse_f64, recording, DeckInputs, InputError, InputFile, SourceFile, Token};
use crate::system::{Model, SimBox, SpecialBonds};
use crate::topology::{BoxAxis, Topology};
use crate::units::UnitSystem;

mod commands;
mod compose;
mod edits;
mod foreign;
mod output_names;
mod outputs;
mod protocols;
mod settings;
mod setup;
mod targets;

pub use self::commands::{command_docs, CommandDoc};

/// The state of a deck being validated: what its commands so far defined.
#[derive(Clone)]
pub(super) struct Validator {
    deck_dir: PathBuf,
    pub(super) vars: Variables,
    /// The setup commands seen so far.
    setup: Setup,
    /// The system as first built (the plan's starting point).
    initial: Initial,
    /// A working copy that `coeff` edits, so each edit is validated against
    /// the parameter values in force at that point of the deck.
    model: Option<Model>,
    groups: HashMap<String, Group>,
    /// The output files named so far.
    outputs: Outputs,
    externals: HashSet<String>,
    timestep_set: bool,
    pub(super) actions: Vec<Action>,
    /// Ramps waiting for a run, moving and frozen groups, reset rest lengths.
    protocols: protocols::Protocols,
    pub(super) control: ControlState,
    /// The last command validated (where a deck-level error is reported).
    pub(super) last: Option<Token>,
    warnings: Vec<String>,
}

/// The setup commands seen so far (`units`, `topology`, `forcefield`,
/// `box`, `special_bonds`), from which the system is built at its first use.
#[derive(Clone)]
struct Setup {
    units: UnitSystem,
    /// Shared, as the system built from it: a branch is validated on a copy
    /// of the validator, which must not copy a 10⁵-term system each time.
    topology: Option<Arc<Topology>>,
    forcefield: ForceField,
    forcefield_seen: bool,
    box_axes: Option<[BoxAxis; 3]>,
    special_bonds: SpecialBonds,
}

/// The system as first built: the plan's model, positions and box.
#[derive(Clone, Default)]
struct Initial {
    model: Option<Arc<Model>>,
    positions: Vec<DVec3>,
    sim_box: Option<SimBox>,
}

/// The output files the deck names: which paths it may write, its open
/// dumps, every output file by kind, and the states it writes.
#[derive(Clone)]
struct Outputs {
    allow_outside: bool,
    dumps: HashMap<String, PathBuf>,
    /// Every output file named so far, by kind (one file, one writer).
    names: output_names::OutputNames,
    states_written: HashSet<PathBuf>,
}

/// How a deck is validated.
#[derive(Clone, Copy, Debug, Default)]
pub struct ValidateOptions {
    /// Accept output paths outside the output directory (absolute, or with
    /// a `..` component): `cellmd run --allow-outside`.
    pub allow_outside: bool,
}

/// An expression parameter of an `external`: its name token and its expression.
type NamedExpr = (Token, DeckExpr);

fn expect_len(s: &[Token], range: std::ops::RangeInclusive<usize>, usage: &str) -> Result<(), InputError> {
    let n = s.len() - 1;
    if range.contains(&n) {
        return Ok(());
    }
    let at = if n > *range.end() { &s[*range.end() + 1] } else { s.last().unwrap() };
    let what = if n > *range.end() { "too many arguments" } else { "too few arguments" };
    // Each form quoted on its own: a quote is clipped past 80 characters.
    let forms: Vec<String> = usage.split(" | ").map(|form| format!("`{form}`")).collect();
    let expected = match forms.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => forms.concat(),
    };
    Err(at.error(format!("{what} ({n}); expected {expected}")))
}

fn yes_no(token: &Token) -> Result<bool, InputError> {
    match token.text.as_str() {
        "yes" => Ok(true),
        "no" => Ok(false),
        other => Err(token.error(format!("found `{other}`, expected `yes` or `no`"))),
    }
}

fn positive(token: &Token, what: &str) -> Result<f64, InputError> {
    let v = parse_f64(token, what)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(token.error(format!("found {v}, expected {what} > 0")))
    }
}

fn non_negative(token: &Token, what: &str) -> Result<f64, InputError> {
    let v = parse_f64(token, what)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(token.error(format!("found {v}, expected {what} >= 0")))
    }
}

/// `key value` options after a command; each key at most once.
fn options<'a>(tokens: &'a [Token], allowed: &[&str], usage: &str) -> Result<HashMap<String, &'a Token>, InputError> {
    let mut out = HashMap::new();
    for pair in tokens.chunks(2) {
        let key = &pair[0];
        if !allowed.contains(&key.text.as_str()) {
            return Err(key.error(format!("found option `{}`, expected one of: {} (`{usage}`)", key.text, allowed.join(", "))));
        }
        let value = pair.get(1).ok_or_else(|| key.error(format!("option `{}` has no value; expected `{} VALUE`", key.text, key.text)))?;
        if out.insert(key.text.clone(), value).is_some() {
            return Err(key.error(format!("option `{}` is given twice; expected it once", key.text)));
        }
    }
    Ok(out)
}

impl Validator {
    fn input_path(&self, token: &Token) -> PathBuf {
        let p = Path::new(&token.text);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.deck_dir.join(p)
        }
    }

    /// The output names `other` (a copy that validated a branch) claimed.
    pub(super) fn take_output_names(&mut self, other: &Validator) {
        self.outputs.names = other.outputs.names.clone();
    }

    /// The group a token names (`all` or one a `group` command defined before).
    fn group_named(&self, token: &Token) -> Result<&Group, InputError> {
        self.groups.get(&token.text).ok_or_else(|| {
            token.error(format!("found group `{}`, expected `all` or a group defined by a `group` command before", token.text))
        })
    }

    /// The model, built on first use from the setup commands seen so far.
    pub(super) fn model(&mut self, at: &Token) -> Result<&mut Model, InputError> {
        if self.model.is_none() {
            let (model, positions, sim_box) = self.setup.build(at)?;
            self.initial = Initial { model: Some(Arc::new(model.clone())), positions, sim_box: Some(sim_box) };
            self.groups.insert("all".into(), Group { name: "all".into(), members: (0..model.len() as u32).collect() });
            self.model = Some(model);
        }
        Ok(self.model.as_mut().unwrap())
    }
}

impl Setup {
    /// The system the setup commands define (the model, its positions and
    /// box), checked; `at` is the command that first needs it.
    fn build(&self, at: &Token) -> Result<(Model, Vec<DVec3>, SimBox), InputError> {
        let topology = self
            .topology
            .as_ref()
            .ok_or_else(|| at.error(format!("`{}` needs a system; expected a `topology FILE` command before it", at.text)))?;
        if !self.forcefield_seen {
            return Err(at.error(format!("`{}` needs a force field; expected a `forcefield FILE` command before it", at.text)));
        }
        let axes = self.box_axes.clone().or_else(|| topology.box_axes.clone()).ok_or_else(|| {
            at.error(format!("no simulation box: expected a `box` command before `{}` or a [ box ] section in {}", at.text, topology.path))
        })?;
        let sim_box = SimBox::new(
            DVec3::new(axes[0].lo, axes[1].lo, axes[2].lo),
            DVec3::new(axes[0].hi, axes[1].hi, axes[2].hi),
            [axes[0].periodic, axes[1].periodic, axes[2].periodic],
        );
        let model = Model::build(topology, &self.forcefield, self.units, self.special_bonds)?;
        check_placement(topology, &model, &sim_box)?;
        check_outward(&model, topology, &sim_box)?;
        Ok((model, topology.positions.clone(), sim_box))
    }
}

impl Outputs {
    /// An output path (relative to the output directory): refused when it
    /// would leave that directory, unless outside paths are allowed.
    fn file(&self, token: &Token) -> Result<PathBuf, InputError> {
        let path = PathBuf::from(&token.text);
        let escapes = path.is_absolute() || path.components().any(|c| matches!(c, std::path::Component::ParentDir));
        if escapes && !self.allow_outside {
            return Err(token.error(format!(
                "found output path `{}` outside the output directory; expected a relative path without `..` \
                 (or `cellmd run --allow-outside`)",
                token.text
            )));
        }
        Ok(path)
    }

    /// [`Self::file`], claimed for a writer of `kind` (see `output_names`).
    fn claim(&mut self, token: &Token, kind: output_names::OutputKind) -> Result<PathBuf, InputError> {
        let path = self.file(token)?;
        self.names.claim(token, &path, kind)?;
        Ok(path)
    }
}

/// Validates a deck given as source text. The plan keeps every input file
/// read (the deck first), so that a restart can carry them.
pub fn validate(file: &std::sync::Arc<SourceFile>, deck_dir: &Path, overrides: &[(String, String)]) -> Result<Plan, InputError> {
    validate_with(file, deck_dir, overrides, ValidateOptions::default())
}

/// [`validate`] with options; the plan records every input file read.
pub fn validate_with(
    file: &std::sync::Arc<SourceFile>,
    deck_dir: &Path,
    overrides: &[(String, String)],
    options: ValidateOptions,
) -> Result<Plan, InputError> {
    let (plan, read) = recording(|| validate_in(&mut Validator::new(deck_dir, overrides, options), file));
    let mut plan = plan?;
    let deck = InputFile { path: file.path.clone(), text: file.text.clone() };
    plan.inputs = DeckInputs {
        deck: file.path.clone(),
        vars: overrides.to_vec(),
        files: std::iter::once(deck.clone()).chain(read.into_iter().filter(|f| *f != deck)).collect(),
    };
    Ok(plan)
}

/// Validates a deck with a fresh `v`, which then holds the deck's context.
pub(super) fn validate_in(v: &mut Validator, file: &std::sync::Arc<SourceFile>) -> Result<Plan, InputError> {
    v.outputs.names.reserve_for_deck(&file.path);
    let last = v.statements(file)?;
    let Some(last) = last else {
        return Err(InputError::in_file(&file.path, "the deck is empty; expected at least `topology`, `forcefield`, `timestep` and `run`"));
    };
    v.model(&last)?;
    v.protocols.finish()?;
    let model = v.initial.model.as_ref().expect("built above");
    let externals: Vec<_> = v.actions.iter().filter_map(|a| if let Action::External(e) = a { Some(e) } else { None }).collect();
    let sim_box = v.initial.sim_box.as_ref().expect("built with the model");
    v.warnings.extend(crate::system::custom_warnings(model, &externals, &v.initial.positions, sim_box));
    Ok(Plan {
        deck_path: PathBuf::from(&file.path),
        model: Arc::unwrap_or_clone(v.initial.model.take().expect("built above")),
        sim_box: v.initial.sim_box.expect("built with the model"),
        // Kept by the validator too: commands validated later (an `OpenDeck`) check
        // expressions at the initial positions.
        positions: v.initial.positions.clone(),
        actions: std::mem::take(&mut v.actions),
        inputs: DeckInputs::default(),
        warnings: std::mem::take(&mut v.warnings),
    })
}

impl Validator {
    pub(super) fn new(deck_dir: &Path, overrides: &[(String, String)], options: ValidateOptions) -> Self {
        Validator {
            deck_dir: deck_dir.to_path_buf(),
            vars: Variables::with_overrides(overrides),
            setup: Setup {
                units: UnitSystem::Cell,
                topology: None,
                forcefield: ForceField::default(),
                forcefield_seen: false,
                box_axes: None,
                special_bonds: SpecialBonds::default(),
            },
            initial: Initial::default(),
            model: None,
            groups: HashMap::new(),
            outputs: Outputs {
                allow_outside: options.allow_outside,
                dumps: HashMap::new(),
                names: Default::default(),
                states_written: HashSet::new(),
            },
            externals: HashSet::new(),
            timestep_set: false,
            actions: Vec::new(),
            protocols: protocols::Protocols::default(),
            control: ControlState::default(),
            last: None,
            warnings: Vec::new(),
        }
    }

    /// Validates every statement of `file` in order, appending to the
    /// actions; returns the keyword of the last command (None: no command).
    pub(super) fn statements(&mut self, file: &std::sync::Arc<SourceFile>) -> Result<Option<Token>, InputError> {
        self.block(&blocks(lex(file)?)?)?;
        Ok(self.last.clone())
    }
}

/// Reads and validates a deck file.
pub fn validate_file(path: &Path, overrides: &[(String, String)]) -> Result<Plan, InputError> {
    validate_file_with(path, overrides, ValidateOptions::default())
}

/// [`validate_file`] with options.
pub fn validate_file_with(path: &Path, overrides: &[(String, String)], options: ValidateOptions) -> Result<Plan, InputError> {
    let file = SourceFile::read(path, None)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    validate_with(&file, &dir, overrides, options)
}

/// Every body must enclose a positive volume at its initial positions (in the
/// deck's box, across periodic boundaries): the topology check proves its faces
/// consistently wound, and this proves them wound outward, which turgor and
/// bending need for their signs.
fn check_outward(model: &Model, topology: &Topology, sim_box: &SimBox) -> Result<(), InputError> {
    let images = sim_box.images();
    for (b, (id, type_token)) in topology.bodies.iter().enumerate() {
        let (volume, _) = model.body_volume_and_area(b, &topology.positions, &images);
        if volume.is_nan() || volume <= 0.0 {
            return Err(type_token.error(format!(
                "body {id} encloses a volume of {volume:e} at its initial positions in this box; expected a positive volume: faces wound \
                 counter-clockwise seen from outside (swap two nodes of every face if they are wound inward)"
            )));
        }
    }
    Ok(())
}
