//! Second phase of deck parsing: command-by-command validation into a [`Plan`].

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::DVec3;

use super::control::{blocks, ControlState};
use super::expression::DeckExpr;
use super::placement::check_placement;
use super::plan::{Action, CheckpointSpec, DumpSpec, Group, NeighborSettings, Plan, ThermoColumn};
use super::variables::Variables;
use crate::expr::{ExprError, Ref};
use crate::forcefield::{load_forcefield, parse_params, ForceField, TermType};
use crate::gpu::DevicePreference;
use crate::input::{
    check_input_file, is_replaying, lex, parse_f64, parse_u64, recording, DeckInputs, InputError, InputFile, SourceFile, Token,
};
use crate::integrate::fire::FireSettings;
use crate::integrate::implicit::{ImplicitSettings, LinearSolver};
use crate::integrate::overdamped::OverdampedSettings;
use crate::integrate::Integrator;
use crate::interactions::{param_index, Kind, REGISTRY};
use crate::kinetics_engine::EventKind;
use crate::output::{AtomColumn, DumpFormat, Encoding, WriterOptions};
use crate::rng::Noise;
use crate::system::{position_or_time, External, Model, SimBox, SpecialBonds};
use crate::topology::{parse_box_axis, BoxAxis, Topology};
use crate::units::UnitSystem;

mod compose;
mod protocols;
mod targets;

/// The commands a deck understands (for "expected ..." messages).
const COMMANDS: &str = "units, variable, loop, endloop, if, else, endif, break, topology, forcefield, box, special_bonds, temperature, timestep, seed, device, integrator, neighbor, thermo, thermo_file, events, lifetimes, dump, undump, group, external, unexternal, displace_atoms, coeff, ramp, move, unmove, freeze, unfreeze, reset_rest, indent, constrain, unconstrain, minimize, run, write_state, read_state, print";

/// Commands that define the system and must come before it is first used.
const SETUP: [&str; 5] = ["units", "topology", "forcefield", "box", "special_bonds"];

/// The state of a deck being validated: what its commands so far defined.
#[derive(Clone)]
pub(super) struct Validator {
    deck_dir: PathBuf,
    pub(super) vars: Variables,
    units: UnitSystem,
    topology: Option<Topology>,
    forcefield: ForceField,
    forcefield_seen: bool,
    box_axes: Option<[BoxAxis; 3]>,
    special_bonds: SpecialBonds,
    /// The system as first built (the plan's starting point).
    initial_model: Option<Model>,
    /// A working copy that `coeff` edits, so each edit is validated against
    /// the parameter values in force at that point of the deck.
    model: Option<Model>,
    positions: Vec<DVec3>,
    sim_box: Option<SimBox>,
    groups: HashMap<String, Group>,
    dumps: HashMap<String, PathBuf>,
    externals: HashSet<String>,
    states_written: HashSet<PathBuf>,
    timestep_set: bool,
    pub(super) actions: Vec<Action>,
    allow_outside: bool,
    /// Ramps waiting for a run, moving and frozen groups, reset rest lengths.
    protocols: protocols::Protocols,
    pub(super) control: ControlState,
    /// The last command validated (where a deck-level error is reported).
    pub(super) last: Option<Token>,
    warnings: Vec<String>,
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

/// Whether a thermo column prefix names a group measurement: (force (`fx`,
/// `fy`, `fz`) or mean unwrapped position (`xu`, `yu`, `zu`), axis).
fn group_column(prefix: &str) -> Option<(bool, usize)> {
    match prefix {
        "fx" | "fy" | "fz" => Some((true, usize::from(prefix.as_bytes()[1] - b'x'))),
        "xu" | "yu" | "zu" => Some((false, usize::from(prefix.as_bytes()[0] - b'x'))),
        _ => None,
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

    /// An output path (relative to the output directory): refused when it
    /// would leave that directory, unless outside paths are allowed.
    fn output_file(&self, token: &Token) -> Result<PathBuf, InputError> {
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

    /// The group a token names (`all` or one a `group` command defined before).
    fn group_named(&self, token: &Token) -> Result<&Group, InputError> {
        self.groups.get(&token.text).ok_or_else(|| {
            token.error(format!("found group `{}`, expected `all` or a group defined by a `group` command before", token.text))
        })
    }

    /// The model, built on first use from the setup commands seen so far.
    pub(super) fn model(&mut self, at: &Token) -> Result<&mut Model, InputError> {
        if self.model.is_none() {
            let topology = self
                .topology
                .as_ref()
                .ok_or_else(|| at.error(format!("`{}` needs a system; expected a `topology FILE` command before it", at.text)))?;
            if !self.forcefield_seen {
                return Err(at.error(format!("`{}` needs a force field; expected a `forcefield FILE` command before it", at.text)));
            }
            let axes = self.box_axes.clone().or_else(|| topology.box_axes.clone()).ok_or_else(|| {
                at.error(format!(
                    "no simulation box: expected a `box` command before `{}` or a [ box ] section in {}",
                    at.text, topology.path
                ))
            })?;
            let sim_box = SimBox::new(
                DVec3::new(axes[0].lo, axes[1].lo, axes[2].lo),
                DVec3::new(axes[0].hi, axes[1].hi, axes[2].hi),
                [axes[0].periodic, axes[1].periodic, axes[2].periodic],
            );
            let model = Model::build(topology, &self.forcefield, self.units, self.special_bonds)?;
            check_placement(topology, &model, &sim_box)?;
            check_outward(&model, topology, &sim_box)?;
            self.positions = topology.positions.clone();
            self.sim_box = Some(sim_box);
            self.groups.insert("all".into(), Group { name: "all".into(), members: (0..model.len() as u32).collect() });
            self.initial_model = Some(model.clone());
            self.model = Some(model);
        }
        Ok(self.model.as_mut().unwrap())
    }

    fn setup_command(&mut self, s: &[Token]) -> Result<(), InputError> {
        let kw = &s[0];
        if self.model.is_some() {
            return Err(kw.error(format!("`{}` changes the system after it was first used; expected it before the first group, external, coeff, run, minimize or state command", kw.text)));
        }
        match kw.text.as_str() {
            "units" => {
                expect_len(s, 1..=1, "units cell|lj")?;
                if self.topology.is_some() || self.forcefield_seen {
                    return Err(kw.error("`units` must come before `topology` and `forcefield`"));
                }
                self.units = UnitSystem::from_keyword(&s[1].text)
                    .ok_or_else(|| s[1].error(format!("found `{}`, expected `cell` (µm, s, pN) or `lj`", s[1].text)))?;
            }
            "topology" => self.topology_command(s)?,
            "forcefield" => {
                expect_len(s, 1..=1, "forcefield FILE")?;
                let path = self.input_path(&s[1]);
                load_forcefield(&path, Some(&s[1]), self.units, &mut self.forcefield, &mut Vec::new())?;
                self.forcefield_seen = true;
            }
            "box" => {
                expect_len(s, 12..=12, "box x LO HI p|f y LO HI p|f z LO HI p|f")?;
                let mut axes: [BoxAxis; 3] = std::array::from_fn(|_| BoxAxis { lo: 0.0, hi: 0.0, periodic: false });
                let mut seen = [false; 3];
                for chunk in s[1..].chunks(4) {
                    let index = parse_box_axis(chunk, &mut axes)?;
                    if seen[index] {
                        return Err(chunk[0].error("axis given twice; expected x, y and z once each"));
                    }
                    seen[index] = true;
                }
                self.box_axes = Some(axes);
            }
            "special_bonds" => {
                // LAMMPS' own form names the pair style family first: `special_bonds lj W12 W13 W14`.
                let s = if s.get(1).is_some_and(|t| t.text == "lj") { [&s[..1], &s[2..]].concat() } else { s.to_vec() };
                expect_len(&s, 3..=3, "special_bonds [lj] W12 W13 W14   (each from 0 = excluded to 1 = in full)")?;
                let mut weights = [0.0; 3];
                for (k, t) in s[1..].iter().enumerate() {
                    weights[k] = parse_f64(t, "a weight")?;
                    if !(0.0..=1.0).contains(&weights[k]) {
                        return Err(
                            t.error(format!("found weight {}, expected a weight from 0 (pair left out) to 1 (pair in full)", weights[k]))
                        );
                    }
                }
                self.special_bonds = SpecialBonds { weights };
            }
            _ => unreachable!(),
        }
        Ok(())
    }

    pub(super) fn thermo_columns(&self, tokens: &[Token]) -> Result<Vec<ThermoColumn>, InputError> {
        const FIXED: &str =
            "step, time, pe, work, pe/NAME, pe/EXTERNAL, fmax, fnorm, press, pxx, pyy, pzz, pxy, pxz, pyz, nbuild, solver_iterations, solver_residual, ctension/BONDTYPE, breaks, rebinds, forms, resets, nbound/BONDTYPE, tension/BONDTYPE, volume/BODYTYPE, area/BODYTYPE, planetension/AXIS/POS, gamma/BODYTYPE, e2e/BONDTYPE, tcorr/BONDTYPE/LAG, fracture/BONDTYPE/QUANTITY, fx/GROUP, fy/GROUP, fz/GROUP, fx/EXTERNAL, fy/EXTERNAL, fz/EXTERNAL, xu/GROUP, yu/GROUP, zu/GROUP, load/INDENTER, depth/INDENTER, mindist, nclamp";
        let bond_type = |t: &Token, name: &str| {
            self.forcefield.bond_types.iter().position(|b| b.label.text == name).ok_or_else(|| {
                let names: Vec<&str> = self.forcefield.bond_types.iter().map(|b| b.label.text.as_str()).collect();
                t.error(format!("found bond type `{name}`, expected one defined in the force field ({})", names.join(", ")))
            })
        };
        let body_type = |t: &Token, name: &str| {
            let names = self.forcefield.body_type_names();
            names.iter().position(|n| *n == name).ok_or_else(|| {
                t.error(format!(
                    "found body type `{name}`, expected one that `body` or `contact` lines of the force field name ({})",
                    names.join(", ")
                ))
            })
        };
        tokens
            .iter()
            .map(|t| {
                Ok(match t.text.as_str() {
                    "step" => ThermoColumn::Step,
                    "time" => ThermoColumn::Time,
                    "pe" => ThermoColumn::Pe,
                    "work" => ThermoColumn::Work,
                    "fmax" => ThermoColumn::Fmax,
                    "fnorm" => ThermoColumn::Fnorm,
                    "press" => ThermoColumn::Press,
                    "pxx" => ThermoColumn::Pressure(0),
                    "pyy" => ThermoColumn::Pressure(1),
                    "pzz" => ThermoColumn::Pressure(2),
                    "pxy" => ThermoColumn::Pressure(3),
                    "pxz" => ThermoColumn::Pressure(4),
                    "pyz" => ThermoColumn::Pressure(5),
                    "nbuild" => ThermoColumn::Nbuild,
                    "solver_iterations" => ThermoColumn::SolverIterations,
                    "solver_residual" => ThermoColumn::SolverResidual,
                    "breaks" => ThermoColumn::Events(EventKind::Break),
                    "rebinds" => ThermoColumn::Events(EventKind::Rebind),
                    "forms" => ThermoColumn::Events(EventKind::Form),
                    "resets" => ThermoColumn::Events(EventKind::Reset),
                    "mindist" | "nclamp" if self.forcefield.contact_rules.is_empty() => {
                        return Err(t.error(format!("found `{}`, which needs `contact` lines in the force field; expected {FIXED}", t.text)))
                    }
                    "mindist" => ThermoColumn::MinDistance,
                    "nclamp" => ThermoColumn::ContactClamps,
                    other => match other.split_once('/') {
                        Some(("pe", name)) => match (REGISTRY.iter().position(|i| i.name() == name), self.externals.contains(name)) {
                            (Some(_), true) => {
                                return Err(t.error(format!(
                                "found `pe/{name}`, which names both an interaction and an active external; expected an external named \
                                 otherwise than every interaction"
                            )))
                            }
                            (Some(k), false) => ThermoColumn::PeOf(k),
                            (None, true) => ThermoColumn::ExternalEnergy(name.to_string()),
                            (None, false) => {
                                return Err(t.error(format!(
                                    "found `pe/{name}`, expected pe/ followed by a registered interaction name (see `cellmd list`) or \
                                 the name of an active external"
                                )))
                            }
                        },
                        Some((prefix, name)) if self.externals.contains(name) && group_column(prefix).is_some_and(|(force, _)| force) => {
                            if self.groups.contains_key(name) {
                                return Err(t.error(format!(
                                    "found `{other}`, where `{name}` names both a group and an active external; expected an external \
                                     named otherwise than every group"
                                )));
                            }
                            ThermoColumn::ExternalForce { name: name.to_string(), axis: group_column(prefix).expect("matched").1 }
                        }
                        Some(("nbound", name)) => ThermoColumn::Bound(bond_type(t, name)?),
                        Some(("tension", name)) => ThermoColumn::Tension(bond_type(t, name)?),
                        Some(("ctension", name)) => ThermoColumn::ConstraintTension(bond_type(t, name)?),
                        Some(("volume", name)) => ThermoColumn::BodyVolume(body_type(t, name)?),
                        Some(("area", name)) => ThermoColumn::BodyArea(body_type(t, name)?),
                        Some(("gamma", name)) => ThermoColumn::CorticalTension(body_type(t, name)?),
                        Some(("e2e", name)) => ThermoColumn::EndToEnd(bond_type(t, name)?),
                        Some((prefix, name)) if group_column(prefix).is_some() => {
                            let (force, axis) = group_column(prefix).expect("matched");
                            let group = self.group_named(&t.with_text(name.to_string()))?.clone();
                            if force {
                                ThermoColumn::GroupForce { group, axis }
                            } else {
                                ThermoColumn::GroupPosition { group, axis }
                            }
                        }
                        Some((kind @ ("load" | "depth"), name)) => self.indenter_column(t, kind, name)?,
                        Some(("planetension", rest)) => {
                            let usage = format!("found `{other}`, expected planetension/AXIS/POS with AXIS x, y or z and POS a number");
                            let (axis, pos) = rest.split_once('/').ok_or_else(|| t.error(usage.clone()))?;
                            let axis = ["x", "y", "z"].iter().position(|a| *a == axis).ok_or_else(|| t.error(usage.clone()))?;
                            let pos = pos.parse::<f64>().ok().filter(|p| p.is_finite()).ok_or_else(|| t.error(usage))?;
                            ThermoColumn::PlaneTension { axis, pos }
                        }
                        Some(("tcorr", rest)) => {
                            let usage = format!("found `{other}`, expected tcorr/BONDTYPE/LAG with LAG a whole number of bonds");
                            let (name, lag) = rest.rsplit_once('/').ok_or_else(|| t.error(usage.clone()))?;
                            let lag = lag.parse::<usize>().map_err(|_| t.error(usage))?;
                            ThermoColumn::TangentCorrelation { bond_type: bond_type(t, name)?, lag }
                        }
                        Some(("fracture", rest)) => {
                            use crate::measure::fracture::FractureQuantity;
                            let names: Vec<&str> = FractureQuantity::ALL.iter().map(|q| q.name()).collect();
                            let usage =
                                format!("found `{other}`, expected fracture/BONDTYPE/QUANTITY with QUANTITY one of {}", names.join(", "));
                            let (name, quantity) = rest.rsplit_once('/').ok_or_else(|| t.error(usage.clone()))?;
                            let quantity = FractureQuantity::from_name(quantity).ok_or_else(|| t.error(usage))?;
                            ThermoColumn::Fracture { bond_type: bond_type(t, name)?, quantity }
                        }
                        _ => return Err(t.error(format!("found thermo column `{other}`, expected one of: {FIXED}"))),
                    },
                })
            })
            .collect()
    }

    /// The options after a `dump`'s file: `columns C...` (LAMMPS dumps) or
    /// `encoding protobuf|json` (MCAP).
    fn dump_options(&self, format: DumpFormat, rest: &[Token], usage: &str) -> Result<WriterOptions, InputError> {
        let mut options = WriterOptions::default();
        let Some(first) = rest.first() else { return Ok(options) };
        match (first.text.as_str(), format) {
            ("columns", DumpFormat::Lammps) => {
                if rest.len() < 2 {
                    return Err(first.error("expected at least one column name after `columns`"));
                }
                options.columns = rest[1..]
                    .iter()
                    .map(|t| {
                        AtomColumn::from_name(&t.text).ok_or_else(|| {
                            let names: Vec<String> = AtomColumn::all().iter().map(|c| c.name()).collect();
                            t.error(format!("found dump column `{}`, expected one of: {}", t.text, names.join(" ")))
                        })
                    })
                    .collect::<Result<_, _>>()?;
            }
            ("encoding", DumpFormat::Mcap) => {
                expect_len(rest, 1..=1, usage)?;
                options.encoding = Encoding::from_keyword(&rest[1].text)
                    .ok_or_else(|| rest[1].error(format!("found encoding `{}`, expected `protobuf` or `json`", rest[1].text)))?;
            }
            ("columns", _) => {
                return Err(first.error(format!("`{}` dumps have fixed fields; expected `columns` only after `lammps`", format.keyword())))
            }
            ("encoding", _) => {
                return Err(first.error(format!("`{}` dumps have one encoding; expected `encoding` only after `mcap`", format.keyword())))
            }
            (other, _) => {
                return Err(first.error(format!("found `{other}`, expected `columns`, `encoding` or the end of the line (`{usage}`)")))
            }
        }
        Ok(options)
    }

    fn group(&mut self, s: &[Token]) -> Result<(), InputError> {
        expect_len(s, 2..=usize::MAX, "group NAME type T... | id N|A:B ... | all")?;
        let name = s[1].text.clone();
        let model = self.model(&s[0])?;
        let n = model.len();
        let mut member = vec![false; n];
        match s[2].text.as_str() {
            "all" => member.iter_mut().for_each(|m| *m = true),
            "type" => {
                if s.len() < 4 {
                    return Err(s[2].error("expected at least one particle type name after `type`"));
                }
                for t in &s[3..] {
                    let ty = model.type_names.iter().position(|n| *n == t.text).ok_or_else(|| {
                        t.error(format!("found particle type `{}`, expected one of: {}", t.text, model.type_names.join(", ")))
                    })?;
                    for (i, m) in member.iter_mut().enumerate() {
                        *m |= model.types[i] as usize == ty;
                    }
                }
            }
            "id" => {
                if s.len() < 4 {
                    return Err(s[2].error("expected at least one id or id range A:B after `id`"));
                }
                let mut by_id: Vec<(u64, u32)> = model.ids.iter().enumerate().map(|(i, &id)| (id, i as u32)).collect();
                by_id.sort_unstable();
                for t in &s[3..] {
                    let (lo, hi) = match t.text.split_once(':') {
                        Some((a, b)) => {
                            let a_tok = t.with_text(a.to_string());
                            let b_tok = t.with_text(b.to_string());
                            (parse_u64(&a_tok, "the first id of a range A:B")?, parse_u64(&b_tok, "the last id of a range A:B")?)
                        }
                        None => {
                            let v = parse_u64(t, "a particle id or range A:B")?;
                            (v, v)
                        }
                    };
                    if hi < lo {
                        return Err(t.error(format!("found range {lo}:{hi}, expected A <= B")));
                    }
                    // By lookup in the sorted ids: the cost is the matches', not the range's.
                    let first = by_id.partition_point(|&(id, _)| id < lo);
                    let matched = by_id[first..].iter().take_while(|&&(id, _)| id <= hi);
                    if matched.clone().next().is_none() {
                        return Err(t.error(format!("`{}` matches no particle; expected ids present in the topology", t.text)));
                    }
                    matched.for_each(|&(_, i)| member[i as usize] = true);
                }
            }
            other => return Err(s[2].error(format!("found `{other}`, expected `type`, `id` or `all`"))),
        }
        let members: Vec<u32> = (0..n as u32).filter(|&i| member[i as usize]).collect();
        if members.is_empty() {
            return Err(s[1].error(format!("group `{name}` is empty; expected a selection that matches particles")));
        }
        self.groups.insert(name.clone(), Group { name, members });
        Ok(())
    }

    /// `write_state FILE [every N [keep K]]`: once now, or periodically
    /// during runs; `*` in FILE stands for the step.
    fn write_state(&mut self, s: &[Token]) -> Result<(), InputError> {
        const USAGE: &str = "write_state FILE [every N [keep K]]";
        expect_len(s, 1..=5, USAGE)?;
        self.model(&s[0])?;
        let path = self.output_file(&s[1])?;
        if s.len() == 2 {
            self.states_written.insert(path.clone());
            self.actions.push(Action::WriteState(path));
            return Ok(());
        }
        if s[2].text != "every" {
            return Err(s[2].error(format!("found `{}`, expected `every` or the end of the line (`{USAGE}`)", s[2].text)));
        }
        let n = s.get(3).ok_or_else(|| s[2].error(format!("`every` has no value; expected `{USAGE}`")))?;
        let every = parse_u64(n, "a checkpoint interval in steps")?;
        if every == 0 {
            return Err(n.error("found 0, expected a checkpoint interval >= 1"));
        }
        let keep = match s.get(4) {
            None => None,
            Some(k) if k.text != "keep" => {
                return Err(k.error(format!("found `{}`, expected `keep` or the end of the line (`{USAGE}`)", k.text)))
            }
            Some(k) => {
                let count = s.get(5).ok_or_else(|| k.error(format!("`keep` has no value; expected `{USAGE}`")))?;
                let keep = parse_u64(count, "a number of checkpoint files to keep")?;
                if keep == 0 {
                    return Err(count.error("found 0, expected keep >= 1"));
                }
                if !s[1].text.contains('*') {
                    return Err(count.error(format!(
                        "`keep` needs a `*` (the step) in the file name; `{}` is one file, overwritten at each checkpoint",
                        s[1].text
                    )));
                }
                Some(keep as usize)
            }
        };
        self.actions.push(Action::Checkpoint(CheckpointSpec { path, every, keep }));
        Ok(())
    }

    /// `displace_atoms GROUP move DX DY DZ` (LAMMPS' syntax, lengths in box units).
    fn displace_atoms(&mut self, s: &[Token]) -> Result<(), InputError> {
        const USAGE: &str = "displace_atoms GROUP move DX DY DZ";
        expect_len(s, 5..=5, USAGE)?;
        self.model(&s[0])?;
        let group = self.group_named(&s[1])?.clone();
        if s[2].text != "move" {
            return Err(s[2].error(format!("found style `{}`, expected `move` (`{USAGE}`)", s[2].text)));
        }
        let mut delta = DVec3::ZERO;
        for (a, (t, name)) in s[3..].iter().zip(["DX", "DY", "DZ"]).enumerate() {
            delta[a] = parse_f64(t, &format!("a displacement {name} (length)"))?;
        }
        self.actions.push(Action::Displace { group, delta });
        Ok(())
    }

    fn coeff(&mut self, s: &[Token]) -> Result<(), InputError> {
        const USAGE: &str = "coeff bond|angle NAME PARAM VALUE ... | coeff pair A B PARAM VALUE ... | coeff body TYPE LAW PARAM VALUE ... | coeff external NAME PARAM VALUE ...";
        expect_len(s, 3..=usize::MAX, USAGE)?;
        let units = self.units;
        let (targets, start) = self.coeff_targets(s, USAGE)?;
        if !(s.len() - start).is_multiple_of(2) || s.len() == start {
            return Err(s.last().unwrap().error("expected `PARAM VALUE` pairs"));
        }
        let mut edits = Vec::new();
        for target in targets {
            for pair in s[start..].chunks(2) {
                let index = self.target_param(&target, &pair[0])?;
                let spec = &target.term_mut(self.model(&pair[0])?).interaction.params()[index];
                let value = parse_f64(&pair[1], &format!("a value for `{}` in {}", spec.name, units.label(spec.dim)))?;
                self.set_target_param(&target, index, value, &pair[1])?;
                edits.push(Action::Coeff { target: target.clone(), param: index, value });
            }
        }
        self.actions.extend(edits);
        Ok(())
    }

    /// The `name value` tokens of an `external` with each expression value
    /// (one that is not a number) replaced by its value at the group's first
    /// member at t = 0, for the schema's checks; and the expressions, deck
    /// variables folded in, with their value tokens.
    fn external_expressions(&self, pairs: &[Token], group: &Group) -> Result<(Vec<Token>, Vec<NamedExpr>), InputError> {
        let mut values = pairs.to_vec();
        let mut expressions = Vec::new();
        for k in (1..pairs.len()).step_by(2) {
            if parse_f64(&pairs[k], "").is_ok() {
                continue;
            }
            let mut expr = DeckExpr::parse(std::slice::from_ref(&pairs[k]))?;
            for (r, span) in expr.expr.refs() {
                let known = matches!(r, Ref::Name("x" | "y" | "z" | "t"));
                if let (Ref::Name(name), false) = (r, known) {
                    self.vars.number(name).map_err(|message| expr.error(&ExprError { span, message }))?;
                }
            }
            expr.expr = expr.expr.substitute(&|name| self.vars.number(name).ok().filter(|_| !matches!(name, "x" | "y" | "z" | "t")));
            let first = group.members.first().copied().unwrap_or(0);
            let x = self.positions[first as usize];
            let value = expr.expr.eval(&mut |r| position_or_time(r, x, 0.0)).map_err(|e| self.at_particle(&expr, &e, first))?;
            values[k] = pairs[k].with_text(format!("{value}"));
            expressions.push((pairs[k - 1].clone(), expr));
        }
        Ok((values, expressions))
    }

    /// Checks each expression parameter at every member's initial position
    /// at t = 0 (domain, the parameter's range, the law's own checks).
    fn check_external_expressions(
        &self,
        term: &TermType,
        group: &Group,
        expressions: Vec<NamedExpr>,
    ) -> Result<Vec<(usize, crate::expr::Expr)>, InputError> {
        let indexed: Vec<(usize, DeckExpr)> = expressions
            .into_iter()
            .map(|(name, expr)| (param_index(term.interaction, &name.text).expect("checked by parse_params"), expr))
            .collect();
        for &m in &group.members {
            let x = self.positions[m as usize];
            let mut params = term.params.clone();
            for (k, expr) in &indexed {
                params[*k] = expr.expr.eval(&mut |r| position_or_time(r, x, 0.0)).map_err(|e| self.at_particle(expr, &e, m))?;
                let spec = &term.interaction.params()[*k];
                spec.check(params[*k])
                    .map_err(|why| self.at_particle(expr, &ExprError { span: expr.expr.span(), message: format!("expected {why}") }, m))?;
            }
            term.interaction.validate(&params).map_err(|why| {
                let (_, first) = &indexed[0];
                let message = format!("invalid `{}` parameters: expected {why}", term.interaction.name());
                self.at_particle(first, &ExprError { span: first.expr.span(), message }, m)
            })?;
        }
        Ok(indexed.into_iter().map(|(k, e)| (k, e.expr)).collect())
    }

    /// An error of an external's expression evaluated at particle `m`'s initial position.
    fn at_particle(&self, expr: &DeckExpr, e: &ExprError, m: u32) -> InputError {
        let mut located = expr.error(e);
        let id = self.model.as_ref().expect("built").ids[m as usize];
        located.message = format!("at particle {id} (x = {}) and t = 0: {}", self.positions[m as usize], located.message);
        located
    }

    pub(super) fn command(&mut self, s: &[Token]) -> Result<(), InputError> {
        let kw = &s[0];
        match kw.text.as_str() {
            k if SETUP.contains(&k) => self.setup_command(s)?,
            "temperature" => {
                expect_len(s, 1..=1, "temperature T")?;
                let what = match self.units {
                    UnitSystem::Cell => "a temperature in K",
                    UnitSystem::Lj => "a reduced temperature kT",
                };
                let t = non_negative(&s[1], what)?;
                if self.units == UnitSystem::Cell && t > 0.0 && t < 1.0 {
                    self.warnings.push(format!(
                        "{}:{}:{}: warning: temperature {t} K; did you mean kT? temperature is in kelvin (kT = {:.3e} pN·µm at 300 K)",
                        s[1].file.path,
                        s[1].line,
                        s[1].col,
                        self.units.kt(300.0)
                    ));
                }
                self.actions.push(Action::Temperature(self.units.kt(t)));
            }
            "timestep" => {
                expect_len(s, 1..=1, "timestep DT")?;
                self.actions.push(Action::Timestep(positive(&s[1], "a timestep")?));
                self.timestep_set = true;
            }
            "seed" => {
                expect_len(s, 1..=1, "seed N")?;
                self.actions.push(Action::Seed(parse_u64(&s[1], "a random seed")?));
            }
            "device" => {
                expect_len(s, 1..=1, "device cpu|gpu|auto")?;
                let device = DevicePreference::from_keyword(&s[1].text)
                    .ok_or_else(|| s[1].error(format!("found device `{}`, expected `cpu`, `gpu` or `auto`", s[1].text)))?;
                self.actions.push(Action::Device(device));
            }
            "integrator" => {
                const USAGE: &str = "integrator overdamped|implicit [noise uniform|gaussian] [max_displacement D] \
                                     [solver cg|cholesky] [tolerance T] [max_iterations N]";
                expect_len(s, 1..=11, USAGE)?;
                let implicit = match s[1].text.as_str() {
                    "overdamped" => false,
                    "implicit" => true,
                    other => return Err(s[1].error(format!("found integrator `{other}`, expected `overdamped` or `implicit`"))),
                };
                let keys: &[&str] = if implicit {
                    &["noise", "max_displacement", "solver", "tolerance", "max_iterations"]
                } else {
                    &["noise", "max_displacement"]
                };
                let opts = options(&s[2..], keys, USAGE)?;
                let mut settings = OverdampedSettings::default();
                if let Some(t) = opts.get("noise") {
                    settings.noise = match t.text.as_str() {
                        "uniform" => Noise::Uniform,
                        "gaussian" => Noise::Gaussian,
                        other => return Err(t.error(format!("found `{other}`, expected `uniform` or `gaussian`"))),
                    };
                }
                if let Some(t) = opts.get("max_displacement") {
                    settings.max_displacement = positive(t, "a maximum displacement per step")?;
                }
                let mut choice = Integrator::Overdamped(settings);
                if implicit {
                    let mut solve = ImplicitSettings::default();
                    if let Some(t) = opts.get("solver") {
                        solve.solver = match t.text.as_str() {
                            "cg" => LinearSolver::Cg,
                            "cholesky" => LinearSolver::Cholesky,
                            other => return Err(t.error(format!("found solver `{other}`, expected `cg` or `cholesky`"))),
                        };
                    }
                    if let Some(t) = opts.get("tolerance") {
                        solve.tolerance = positive(t, "a relative residual tolerance")?;
                    }
                    if let Some(t) = opts.get("max_iterations") {
                        solve.max_iterations = parse_u64(t, "an iteration count")?.max(1) as usize;
                    }
                    choice = Integrator::Implicit(settings, solve);
                }
                self.actions.push(Action::Integrator(choice));
            }
            "neighbor" => {
                expect_len(s, 2..=6, "neighbor skin S [every N] [check yes|no]")?;
                let opts = options(&s[1..], &["skin", "every", "check"], "neighbor skin S [every N] [check yes|no]")?;
                let mut n = NeighborSettings::default();
                if let Some(t) = opts.get("skin") {
                    n.skin = non_negative(t, "a skin distance")?;
                }
                if let Some(t) = opts.get("every") {
                    n.every = parse_u64(t, "a step interval")?.max(1);
                }
                if let Some(t) = opts.get("check") {
                    n.check = yes_no(t)?;
                }
                self.actions.push(Action::Neighbor(n));
            }
            "thermo" => {
                expect_len(s, 1..=usize::MAX, "thermo N [column ...]")?;
                let every = parse_u64(&s[1], "a thermo interval in steps")?;
                let columns = if s.len() > 2 {
                    // Group columns name groups, which exist once the system does.
                    if let Some(t) = s[2..].iter().find(|t| t.text.split_once('/').is_some_and(|(p, _)| group_column(p).is_some())) {
                        self.model(t)?;
                    }
                    self.thermo_columns(&s[2..])?
                } else {
                    vec![ThermoColumn::Step, ThermoColumn::Time, ThermoColumn::Pe, ThermoColumn::Fmax, ThermoColumn::Press]
                };
                self.actions.push(Action::Thermo { every, columns });
            }
            "thermo_file" => {
                expect_len(s, 1..=1, "thermo_file FILE.csv")?;
                self.actions.push(Action::ThermoFile(self.output_file(&s[1])?));
            }
            "events" => {
                expect_len(s, 1..=1, "events FILE.csv")?;
                self.actions.push(Action::EventFile(self.output_file(&s[1])?));
            }
            "lifetimes" => {
                expect_len(s, 1..=1, "lifetimes FILE.csv")?;
                self.actions.push(Action::LifetimeFile(self.output_file(&s[1])?));
            }
            "dump" => {
                const USAGE: &str = "dump NAME every N mcap|xyz|lammps|bonds|dcd FILE [columns COLUMN...] [encoding protobuf|json]";
                expect_len(s, 5..=usize::MAX, USAGE)?;
                if s[2].text != "every" {
                    return Err(s[2].error(format!("found `{}`, expected `every`", s[2].text)));
                }
                let every = parse_u64(&s[3], "a dump interval in steps")?;
                if every == 0 {
                    return Err(s[3].error("found 0, expected a dump interval >= 1"));
                }
                let format = DumpFormat::from_keyword(&s[4].text).ok_or_else(|| {
                    let names: Vec<String> = DumpFormat::ALL.iter().map(|f| format!("`{}`", f.keyword())).collect();
                    s[4].error(format!("found format `{}`, expected one of {}", s[4].text, names.join(", ")))
                })?;
                let path = self.output_file(&s[5])?;
                let options = self.dump_options(format, &s[6..], USAGE)?;
                if self.dumps.contains_key(&s[1].text) {
                    return Err(
                        s[1].error(format!("dump `{}` is already active; expected a new name or `undump {}` first", s[1].text, s[1].text))
                    );
                }
                if self.dumps.values().any(|p| *p == path) {
                    return Err(s[5].error(format!("`{}` is already written by another dump; expected a different file", s[5].text)));
                }
                self.dumps.insert(s[1].text.clone(), path.clone());
                self.actions.push(Action::Dump(DumpSpec { name: s[1].text.clone(), every, format, path, options }));
            }
            "undump" => {
                expect_len(s, 1..=1, "undump NAME")?;
                if self.dumps.remove(&s[1].text).is_none() {
                    return Err(s[1].error(format!("found `{}`, expected the name of an active dump", s[1].text)));
                }
                self.actions.push(Action::Undump(s[1].text.clone()));
            }
            "group" => self.group(s)?,
            "external" => {
                expect_len(s, 3..=usize::MAX, "external NAME GROUP INTERACTION [param value]...")?;
                self.protocols.check_external_kept(&s[1])?;
                let units = self.units;
                self.model(kw)?;
                let group = self.group_named(&s[2])?.clone();
                let (term, expressions) = if s[3].text == "custom" {
                    crate::forcefield::parse_custom_external(&s[1], &s[3], &s[4..], units)?
                } else {
                    let (values, expressions) = self.external_expressions(&s[4..], &group)?;
                    let term = parse_params(&s[1], &s[3], &values, Kind::External, units)?;
                    let expressions = self.check_external_expressions(&term, &group, expressions)?;
                    (term, expressions)
                };
                let external = External { term, group: group.name.clone(), members: group.members.clone(), expressions };
                self.externals.insert(s[1].text.clone());
                // The working model holds the active externals for `coeff` and `ramp`.
                let model = self.model(kw)?;
                model.externals.retain(|e| e.term.label.text != s[1].text);
                model.externals.push(external.clone());
                self.actions.push(Action::External(external));
            }
            "unexternal" => {
                expect_len(s, 1..=1, "unexternal NAME")?;
                self.protocols.check_external_kept(&s[1])?;
                if !self.externals.remove(&s[1].text) {
                    return Err(s[1].error(format!("found `{}`, expected the name of an active external", s[1].text)));
                }
                if let Some(model) = self.model.as_mut() {
                    model.externals.retain(|e| e.term.label.text != s[1].text);
                }
                self.actions.push(Action::Unexternal(s[1].text.clone()));
            }
            "displace_atoms" => self.displace_atoms(s)?,
            "coeff" => self.coeff(s)?,
            "ramp" | "move" | "unmove" | "freeze" | "unfreeze" | "reset_rest" | "indent" => self.protocol_command(s)?,
            "constrain" | "unconstrain" => {
                let usage =
                    if kw.text == "constrain" { "constrain BONDTYPE [tolerance T] [max_iterations N]" } else { "unconstrain BONDTYPE" };
                expect_len(s, 1..=5, usage)?;
                let opts = if kw.text == "constrain" {
                    options(&s[2..], &["tolerance", "max_iterations"], usage)?
                } else {
                    options(&s[2..], &[], usage)?
                };
                let model = self.model(kw)?;
                let bond_type = model
                    .bond_types
                    .iter()
                    .position(|t| t.label.text == s[1].text)
                    .ok_or_else(|| s[1].error(format!("found bond type `{}`, expected one defined in the force field", s[1].text)))?;
                let term = &model.bond_types[bond_type];
                if param_index(term.interaction, "r0").is_none() {
                    return Err(s[1].error(format!(
                        "bond type `{}` uses `{}`, which has no rest length r0; expected a bond type whose law has one",
                        s[1].text,
                        term.interaction.name()
                    )));
                }
                if !model.bond_kinetics[bond_type].rules.is_empty() {
                    return Err(
                        s[1].error(format!("bond type `{}` has kinetics; expected a bond type whose bonds never change", s[1].text))
                    );
                }
                if kw.text == "unconstrain" {
                    self.actions.push(Action::Unconstrain(bond_type));
                } else {
                    let tolerance = opts.get("tolerance").map(|t| positive(t, "a relative length tolerance")).transpose()?.unwrap_or(1e-10);
                    let max_iterations =
                        opts.get("max_iterations").map(|t| parse_u64(t, "a sweep count")).transpose()?.unwrap_or(1000).max(1) as usize;
                    self.actions.push(Action::Constrain { bond_type, tolerance, max_iterations });
                }
            }
            "minimize" => {
                let usage = "minimize [ftol F] [maxiter N] [dmax D]";
                let opts = options(&s[1..], &["ftol", "maxiter", "dmax"], usage)?;
                let mut f = FireSettings::default();
                if let Some(t) = opts.get("ftol") {
                    f.ftol = positive(t, "a force tolerance")?;
                }
                if let Some(t) = opts.get("maxiter") {
                    f.max_iterations = parse_u64(t, "a maximum number of iterations")?;
                }
                if let Some(t) = opts.get("dmax") {
                    f.dmax = positive(t, "a maximum move per iteration")?;
                }
                self.model(kw)?;
                if !self.timestep_set {
                    return Err(kw.error("`minimize` scales FIRE's step from the timestep; expected a `timestep DT` command before it"));
                }
                self.actions.push(Action::Minimize(f));
            }
            "run" => {
                expect_len(s, 1..=1, "run N")?;
                let n = parse_u64(&s[1], "a number of steps")?;
                self.model(kw)?;
                if !self.timestep_set {
                    return Err(kw.error("no timestep; expected a `timestep DT` command before `run`"));
                }
                self.protocols.run();
                self.actions.push(Action::Run(n));
            }
            "write_state" => self.write_state(s)?,
            "read_state" => {
                expect_len(s, 1..=1, "read_state FILE")?;
                self.model(kw)?;
                let written = PathBuf::from(&s[1].text);
                let path = if self.states_written.contains(&written) { written } else { self.input_path(&s[1]) };
                // A continued run starts after this point from its own restart.
                if !self.states_written.contains(&path) && !is_replaying() {
                    if !path.exists() {
                        return Err(s[1].error(format!(
                            "cannot read `{}`: no such file; expected a restart file written by `write_state`",
                            path.display()
                        )));
                    }
                    check_input_file(&path).map_err(|why| s[1].error(format!("cannot read `{}`: {why}", path.display())))?;
                }
                self.actions.push(Action::ReadState(path));
            }
            "print" => self.actions.push(Action::Print(s[1..].iter().map(|t| t.text.as_str()).collect::<Vec<_>>().join(" "))),
            other => return Err(kw.error(format!("found unknown command `{other}`, expected one of: {COMMANDS}"))),
        }
        Ok(())
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
    let last = v.statements(file)?;
    let Some(last) = last else {
        return Err(InputError::in_file(&file.path, "the deck is empty; expected at least `topology`, `forcefield`, `timestep` and `run`"));
    };
    v.model(&last)?;
    v.protocols.finish()?;
    Ok(Plan {
        deck_path: PathBuf::from(&file.path),
        model: v.initial_model.take().expect("built above"),
        sim_box: v.sim_box.expect("built with the model"),
        // Kept by the validator too: commands validated later (an `OpenDeck`) check
        // expressions at the initial positions.
        positions: v.positions.clone(),
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
            units: UnitSystem::Cell,
            topology: None,
            forcefield: ForceField::default(),
            forcefield_seen: false,
            box_axes: None,
            special_bonds: SpecialBonds::default(),
            initial_model: None,
            model: None,
            positions: Vec::new(),
            sim_box: None,
            groups: HashMap::new(),
            dumps: HashMap::new(),
            externals: HashSet::new(),
            states_written: HashSet::new(),
            timestep_set: false,
            actions: Vec::new(),
            allow_outside: options.allow_outside,
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
