//! Protocol commands: `ramp`, `move`/`unmove`, `freeze`/`unfreeze` and
//! `reset_rest` (see [`crate::deck::Protocol`]).

use std::collections::{BTreeMap, HashMap, HashSet};

use glam::DVec3;

use super::{expect_len, positive, Validator};
use crate::deck::plan::{Action, CoeffTarget, ThermoColumn};
use crate::deck::protocol::{Protocol, Ramp, Velocity};
use crate::expr::ExprError;
use crate::input::{parse_f64, InputError, Token};
use crate::interactions::param_index;
use crate::system::position_or_time;

/// The interaction types whose centre `indent` drives and whose load and
/// depth thermo reports (laws E = (K/3)δ³ with a centre `x y z` and a `k`).
const INDENTERS: [&str; 2] = ["indenter", "flat_punch"];

/// Intermediate fractions of a ramp whose parameter values the law's own
/// checks must accept (besides both ends).
const RAMP_SAMPLES: u32 = 1024;

/// What the protocol commands seen so far leave in force.
#[derive(Clone, Default)]
pub(super) struct Protocols {
    /// Ramps waiting for the next `run`: target, parameter, and the command's keyword.
    pending: Vec<(CoeffTarget, usize, Token)>,
    /// Moving groups: name → members.
    moving: BTreeMap<String, Vec<u32>>,
    /// Frozen groups.
    frozen: HashSet<String>,
    /// Bond types whose rest lengths `reset_rest` set: type → line.
    reset: HashMap<usize, u32>,
}

impl Protocols {
    /// The line of the `reset_rest` that set this bond type's rest lengths.
    pub(super) fn reset_by(&self, target: &CoeffTarget) -> Option<u32> {
        match target {
            CoeffTarget::BondType(k) => self.reset.get(k).copied(),
            _ => None,
        }
    }

    /// Whether a ramp over the next run already changes this parameter.
    pub(super) fn is_ramped(&self, target: &CoeffTarget, param: usize) -> bool {
        self.pending.iter().any(|(t, p, _)| t == target && *p == param)
    }

    /// An external that a pending ramp changes may not be replaced or removed before the run.
    pub(super) fn check_external_kept(&self, name: &Token) -> Result<(), InputError> {
        if self.pending.iter().any(|(t, _, _)| *t == CoeffTarget::External(name.text.clone())) {
            return Err(name.error(format!(
                "external `{}` is ramped over the next `run`; expected to replace or remove it after that run",
                name.text
            )));
        }
        Ok(())
    }

    /// A `run` consumes the pending ramps.
    pub(super) fn run(&mut self) {
        self.pending.clear();
    }

    /// At the end of the deck no ramp may wait for a run that never comes.
    pub(super) fn finish(&self) -> Result<(), InputError> {
        match self.pending.first() {
            Some((_, _, kw)) => Err(kw.error("`ramp` has no `run` after it; expected a `run N` to ramp over")),
            None => Ok(()),
        }
    }
}

impl Validator {
    /// A protocol command: its parser's protocol becomes the plan's action.
    pub(super) fn protocol(
        &mut self,
        s: &[Token],
        usage: &str,
        parse: fn(&mut Validator, &[Token], &str) -> Result<Protocol, InputError>,
    ) -> Result<(), InputError> {
        let protocol = parse(self, s, usage)?;
        self.actions.push(Action::Protocol(protocol));
        Ok(())
    }

    /// `unmove GROUP`, `unfreeze GROUP`: ends the group's protocol.
    pub(super) fn release(&mut self, s: &[Token], usage: &str) -> Result<Protocol, InputError> {
        expect_len(s, 1..=1, usage)?;
        let (active, what) = if s[0].text == "unmove" {
            (self.protocols.moving.remove(&s[1].text).is_some(), "moved")
        } else {
            (self.protocols.frozen.remove(&s[1].text), "frozen")
        };
        if !active {
            return Err(s[1].error(format!("found `{}`, expected a group {what} by a `{}` command before", s[1].text, &s[0].text[2..])));
        }
        Ok(if s[0].text == "unmove" { Protocol::Unmove(s[1].text.clone()) } else { Protocol::Unfreeze(s[1].text.clone()) })
    }

    /// `ramp TARGET PARAM FROM TO`: both ends and [`RAMP_SAMPLES`] values
    /// between them must pass the law's checks; a pair rule's cutoff must
    /// not change (the neighbour list is built for one cutoff per run).
    pub(super) fn ramp(&mut self, s: &[Token], usage: &str) -> Result<Protocol, InputError> {
        expect_len(s, 5..=usize::MAX, usage)?;
        let (targets, start) = self.coeff_targets(s, usage)?;
        expect_len(s, start + 2..=start + 2, usage)?;
        let [name, from_token, to_token] = [&s[start], &s[start + 1], &s[start + 2]];
        let mut ramps = Vec::new();
        for target in targets {
            let param = self.target_param(&target, name)?;
            let interaction = target.term(self.model(name)?).interaction;
            let spec = &interaction.params()[param];
            let what = |end: &str| format!("the {end} value of `{}` in {}", spec.name, self.setup.units.label(spec.dim));
            let from = parse_f64(from_token, &what("start"))?;
            let to = parse_f64(to_token, &what("end"))?;
            let cutoff = self.pair_cutoff(&target, name)?;
            self.set_target_param(&target, param, from, from_token)?;
            let at_from = self.pair_cutoff(&target, name)?;
            self.set_target_param(&target, param, to, to_token)?;
            let at_to = self.pair_cutoff(&target, name)?;
            if let (Some(before), Some(at_from), Some(at_to)) = (cutoff, at_from, at_to) {
                if at_from != before || at_to != before {
                    return Err(name.error(format!(
                        "ramping `{}` moves the pair cutoff ({before} now, {at_from} to {at_to}); expected a parameter that leaves the cutoff alone (change it with `coeff` between runs)",
                        name.text
                    )));
                }
            }
            for k in 1..RAMP_SAMPLES {
                let value = from + (to - from) * f64::from(k) / f64::from(RAMP_SAMPLES);
                self.set_target_param(&target, param, value, to_token)
                    .map_err(|e| to_token.error(format!("the ramp from {from} to {to} passes through {value}, where {}", e.message)))?;
            }
            self.set_target_param(&target, param, to, to_token)?;
            self.protocols.pending.push((target.clone(), param, s[0].clone()));
            ramps.push(Ramp { target, param, from, to });
        }
        // `pair A B` may name several rules: all but the last become actions here.
        let last = ramps.pop().expect("at least one target");
        self.actions.extend(ramps.into_iter().map(|r| Action::Protocol(Protocol::Ramp(r))));
        Ok(Protocol::Ramp(last))
    }

    /// `move GROUP linear VX VY VZ` (velocity in length/time units) or
    /// `move GROUP velocity "VX" "VY" "VZ"` (expressions of x, y, z, t,
    /// checked at every member's initial position at t = 0).
    pub(super) fn move_group(&mut self, s: &[Token], usage: &str) -> Result<Protocol, InputError> {
        expect_len(s, 5..=5, usage)?;
        self.model(&s[0])?;
        let group = self.group_named(&s[1])?.clone();
        let unit = self.setup.units.label(crate::units::Dim::Velocity);
        let components = s[3..].iter().zip(["VX", "VY", "VZ"]);
        let velocity = match s[2].text.as_str() {
            "linear" => {
                let mut velocity = DVec3::ZERO;
                for (a, (t, name)) in components.enumerate() {
                    velocity[a] = parse_f64(t, &format!("a velocity {name} in {unit}"))?;
                }
                Velocity::Constant(velocity)
            }
            "velocity" => {
                let exprs = components.map(|(t, _)| self.position_expression(t)).collect::<Result<Vec<_>, _>>()?;
                for &m in &group.members {
                    let x = self.initial.positions[m as usize];
                    for expr in &exprs {
                        let value = expr.expr.eval(&mut |r| position_or_time(r, x, 0.0)).map_err(|e| self.at_particle(expr, &e, m))?;
                        if !value.is_finite() {
                            let message = format!("found velocity {value}, expected a finite velocity in {unit}");
                            return Err(self.at_particle(expr, &ExprError { span: expr.expr.span(), message }, m));
                        }
                    }
                }
                let field: [crate::expr::Expr; 3] = exprs.into_iter().map(|e| e.expr).collect::<Vec<_>>().try_into().expect("three tokens");
                Velocity::Field(Box::new(field))
            }
            other => return Err(s[2].error(format!("found style `{other}`, expected `linear` or `velocity` (`{usage}`)"))),
        };
        let clash = self
            .protocols
            .moving
            .iter()
            .filter(|(other, _)| **other != group.name)
            .find_map(|(other, members)| group.members.iter().find(|i| members.binary_search(i).is_ok()).map(|&i| (other.clone(), i)));
        if let Some((other, i)) = clash {
            let id = self.model(&s[0])?.ids[i as usize];
            return Err(s[1].error(format!(
                "particle {id} of group `{}` is already moved with group `{other}`; expected groups without common particles (or `unmove {other}` first)",
                group.name
            )));
        }
        self.protocols.moving.insert(group.name.clone(), group.members.clone());
        Ok(Protocol::Move { group, velocity })
    }

    /// `freeze GROUP x|y|z ...`.
    pub(super) fn freeze(&mut self, s: &[Token], usage: &str) -> Result<Protocol, InputError> {
        expect_len(s, 2..=4, usage)?;
        self.model(&s[0])?;
        let group = self.group_named(&s[1])?.clone();
        let mut axes = [false; 3];
        for t in &s[2..] {
            let a = ["x", "y", "z"]
                .iter()
                .position(|a| *a == t.text)
                .ok_or_else(|| t.error(format!("found `{}`, expected an axis `x`, `y` or `z` (`{usage}`)", t.text)))?;
            if std::mem::replace(&mut axes[a], true) {
                return Err(t.error(format!("axis `{}` is given twice; expected each axis once", t.text)));
            }
        }
        self.protocols.frozen.insert(group.name.clone());
        Ok(Protocol::Freeze { group, axes })
    }

    /// `reset_rest BONDTYPE|all`: bond types whose law has a rest length `r0`.
    pub(super) fn reset_rest(&mut self, s: &[Token], usage: &str) -> Result<Protocol, InputError> {
        expect_len(s, 1..=1, usage)?;
        let model = self.model(&s[0])?;
        let with_rest: Vec<usize> =
            (0..model.bond_types.len()).filter(|&t| param_index(model.bond_types[t].interaction, "r0").is_some()).collect();
        let types = if s[1].text == "all" {
            let present: Vec<usize> = with_rest.into_iter().filter(|t| model.bond_type.iter().any(|&b| b as usize == *t)).collect();
            if present.is_empty() {
                return Err(s[1].error("no bond has a law with a rest length r0; expected bonds to reset"));
            }
            present
        } else {
            let t = model.bond_types.iter().position(|t| t.label.text == s[1].text).ok_or_else(|| {
                let names: Vec<&str> = model.bond_types.iter().map(|t| t.label.text.as_str()).collect();
                s[1].error(format!(
                    "found bond type `{}`, expected `all` or one defined in the force field ({})",
                    s[1].text,
                    names.join(", ")
                ))
            })?;
            if !with_rest.contains(&t) {
                return Err(s[1].error(format!(
                    "bond type `{}` uses `{}`, which has no rest length r0; expected a bond type whose law has one",
                    s[1].text,
                    model.bond_types[t].interaction.name()
                )));
            }
            vec![t]
        };
        for &t in &types {
            self.protocols.reset.insert(t, s[0].line);
        }
        Ok(Protocol::ResetRest(types))
    }

    /// The active external `name` names, which must be an indenter.
    fn indenter_named(&self, t: &Token, name: &str) -> Result<(), InputError> {
        let external = self.model.as_ref().and_then(|m| m.externals.iter().find(|e| e.term.label.text == name));
        match external {
            Some(e) if INDENTERS.contains(&e.term.interaction.name()) => Ok(()),
            Some(e) => Err(t.error(format!(
                "external `{name}` is a `{}`; expected the name of an active `{}` external",
                e.term.interaction.name(),
                INDENTERS.join("` or `")
            ))),
            None => Err(t.error(format!("found `{name}`, expected the name of an active `{}` external", INDENTERS.join("` or `")))),
        }
    }

    /// `load/NAME` and `depth/NAME` thermo columns of an active indenter.
    pub(super) fn indenter_column(&self, t: &Token, kind: &str, name: &str) -> Result<ThermoColumn, InputError> {
        self.indenter_named(t, name)?;
        Ok(if kind == "load" { ThermoColumn::IndenterLoad(name.to_string()) } else { ThermoColumn::IndenterDepth(name.to_string()) })
    }

    /// `indent NAME velocity VX VY VZ [until LOAD]` / `indent NAME stop`.
    pub(super) fn indent(&mut self, s: &[Token], usage: &str) -> Result<Protocol, InputError> {
        expect_len(s, 2..=7, usage)?;
        self.model(&s[0])?;
        self.indenter_named(&s[1], &s[1].text)?;
        if self.protocols.pending.iter().any(|(t, _, _)| *t == CoeffTarget::External(s[1].text.clone())) {
            return Err(s[1]
                .error(format!("external `{}` is ramped over the next `run`; expected either a `ramp` or an `indent` of it", s[1].text)));
        }
        let external = s[1].text.clone();
        match s[2].text.as_str() {
            "stop" => {
                expect_len(s, 2..=2, usage)?;
                Ok(Protocol::Indent { external, velocity: DVec3::ZERO, until: None })
            }
            "velocity" => {
                if s.len() != 6 && s.len() != 8 {
                    expect_len(s, 5..=5, usage)?;
                }
                let unit = self.setup.units.label(crate::units::Dim::Velocity);
                let mut velocity = DVec3::ZERO;
                for (a, (t, name)) in s[3..6].iter().zip(["VX", "VY", "VZ"]).enumerate() {
                    velocity[a] = parse_f64(t, &format!("a velocity {name} in {unit}"))?;
                }
                let until = match s.get(6) {
                    None => None,
                    Some(t) if t.text == "until" => {
                        let load = positive(&s[7], &format!("a load in {}", self.setup.units.label(crate::units::Dim::Force)))?;
                        Some(load)
                    }
                    Some(t) => return Err(t.error(format!("found `{}`, expected `until` or the end of the line (`{usage}`)", t.text))),
                };
                Ok(Protocol::Indent { external, velocity, until })
            }
            other => Err(s[2].error(format!("found `{other}`, expected `velocity` or `stop` (`{usage}`)"))),
        }
    }
}
