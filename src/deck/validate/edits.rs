//! Commands that name or edit parts of the system: `group`, `external`,
//! `unexternal`, `displace_atoms`, `coeff`, `constrain` and `unconstrain`.

use glam::DVec3;

use super::{expect_len, options, positive, yes_no, NamedExpr, Validator};
use crate::deck::expression::DeckExpr;
use crate::deck::plan::{Action, Group};
use crate::expr::{ExprError, Ref};
use crate::forcefield::{param_value, parse_params, typed, TermType};
use crate::input::{parse_f64, parse_u64, InputError, Token};
use crate::integrate::constraints::ConstraintMethod;
use crate::interactions::{param_index, Kind};
use crate::system::{position_or_time, External};

/// The largest relative distance from its rest length a constrained bond may
/// start at without `reshape yes` (the first step's projection removes smaller ones).
const MAX_CONSTRAINT_DEFECT: f64 = 0.01;

impl Validator {
    pub(super) fn group(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 2..=usize::MAX, usage)?;
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
        self.spend_bytes(&s[0], 4 * members.len() as u64)?;
        self.groups.insert(name.clone(), Group { name, members });
        Ok(())
    }

    pub(super) fn external(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        let kw = &s[0];
        expect_len(s, 3..=usize::MAX, usage)?;
        self.protocols.check_external_kept(&s[1])?;
        let units = self.setup.units;
        self.model(kw)?;
        let group = self.group_named(&s[2])?.clone();
        let (term, expressions) = if s[3].text == "custom" {
            let (term, expressions) = crate::forcefield::parse_custom_external(&s[1], &s[3], &s[4..], units)?;
            (typed(term, &s[3])?, expressions)
        } else {
            let (values, expressions) = self.external_expressions(&s[4..], &group)?;
            let term = typed(parse_params(&s[1], &s[3], &values, Kind::External, units)?, &s[3])?;
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
        Ok(())
    }

    pub(super) fn unexternal(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        self.protocols.check_external_kept(&s[1])?;
        if !self.externals.remove(&s[1].text) {
            return Err(s[1].error(format!("found `{}`, expected the name of an active external", s[1].text)));
        }
        if let Some(model) = self.model.as_mut() {
            model.externals.retain(|e| e.term.label.text != s[1].text);
        }
        self.actions.push(Action::Unexternal(s[1].text.clone()));
        Ok(())
    }

    pub(super) fn constrain(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        let kw = &s[0];
        expect_len(s, 1..=10, usage)?;
        let opts = if kw.text == "constrain" {
            options(&s[2..], &["tolerance", "max_iterations", "reshape", "method"], usage)?
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
        let Some(r0) = param_index(term.interaction, "r0") else {
            return Err(s[1].error(format!(
                "bond type `{}` uses `{}`, which has no rest length r0; expected a bond type whose law has one",
                s[1].text,
                term.interaction.name()
            )));
        };
        if !model.bond_kinetics[bond_type].rules.is_empty() {
            return Err(s[1].error(format!("bond type `{}` has kinetics; expected a bond type whose bonds never change", s[1].text)));
        }
        if kw.text == "unconstrain" {
            self.actions.push(Action::Unconstrain(bond_type));
            return Ok(());
        }
        let tolerance = opts.get("tolerance").map(|t| positive(t, "a relative length tolerance")).transpose()?.unwrap_or(1e-10);
        let max_iterations = opts.get("max_iterations").map(|t| parse_u64(t, "a sweep count")).transpose()?.unwrap_or(1000).max(1) as usize;
        let method = match opts.get("method") {
            None => ConstraintMethod::Fibre,
            Some(t) => match t.text.as_str() {
                "fibre" => ConstraintMethod::Fibre,
                "shake" => ConstraintMethod::Shake,
                other => return Err(t.error(format!("found method `{other}`, expected `fibre` or `shake`"))),
            },
        };
        let reshape = opts.get("reshape").map(|t| yes_no(t)).transpose()?.unwrap_or(false);
        if !reshape {
            let model = self.model.as_ref().expect("built above");
            let type_r0 = model.bond_types[bond_type].params[r0];
            let images = self.initial.sim_box.as_ref().expect("built with the model").images();
            let worst = (0..model.topology_bonds)
                .filter(|&b| model.bond_type[b] as usize == bond_type)
                .map(|b| {
                    let [i, j] = model.bonds[b];
                    let length = images.minimum_image(self.initial.positions[j as usize] - self.initial.positions[i as usize]).length();
                    let rest = model.bond_rest[b].unwrap_or(type_r0);
                    (b, length, rest, ((length - rest) / rest).abs())
                })
                .fold(None, |worst: Option<(usize, f64, f64, f64)>, c| if worst.is_none_or(|w| c.3 > w.3) { Some(c) } else { worst });
            if let Some((b, length, rest, error)) = worst.filter(|w| !(w.3 <= MAX_CONSTRAINT_DEFECT)) {
                let [i, j] = model.bonds[b].map(|p| model.ids[p as usize]);
                return Err(s[1].error(format!(
                    "bond {i}-{j} of type `{}` is {length:e} long at the topology's positions, {:.3} % off its rest length {rest:e}; \
                     expected every constrained bond within {} % of its rest length, or `constrain {} reshape yes` to move the particles \
                     onto their lengths first",
                    s[1].text,
                    100.0 * error,
                    100.0 * MAX_CONSTRAINT_DEFECT,
                    s[1].text
                )));
            }
        }
        self.actions.push(Action::Constrain { bond_type, tolerance, max_iterations, reshape, method });
        Ok(())
    }

    /// `displace_atoms GROUP move DX DY DZ` (LAMMPS' syntax, lengths in box units).
    pub(super) fn displace_atoms(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 5..=5, usage)?;
        self.model(&s[0])?;
        let group = self.group_named(&s[1])?.clone();
        if s[2].text != "move" {
            return Err(s[2].error(format!("found style `{}`, expected `move` (`{usage}`)", s[2].text)));
        }
        let mut delta = DVec3::ZERO;
        for (a, (t, name)) in s[3..].iter().zip(["DX", "DY", "DZ"]).enumerate() {
            delta[a] = parse_f64(t, &format!("a displacement {name} (length)"))?;
        }
        self.actions.push(Action::Displace { group, delta });
        Ok(())
    }

    pub(super) fn coeff(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 3..=usize::MAX, usage)?;
        let units = self.setup.units;
        let (targets, start) = self.coeff_targets(s, usage)?;
        if !(s.len() - start).is_multiple_of(2) || s.len() == start {
            return Err(s.last().unwrap().error("expected `PARAM VALUE` pairs"));
        }
        let mut edits = Vec::new();
        for target in targets {
            for pair in s[start..].chunks(2) {
                let index = self.target_param(&target, &pair[0])?;
                let value = param_value(&target.term(self.model(&pair[0])?).interaction.params()[index], &pair[1], units)?;
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
            let expr = self.position_expression(&pairs[k])?;
            let first = group.members.first().copied().unwrap_or(0);
            let x = self.initial.positions[first as usize];
            let value = expr.expr.eval(&mut |r| position_or_time(r, x, 0.0)).map_err(|e| self.at_particle(&expr, &e, first))?;
            values[k] = pairs[k].with_text(format!("{value}"));
            expressions.push((pairs[k - 1].clone(), expr));
        }
        Ok((values, expressions))
    }

    /// An expression of the position `x`, `y`, `z` and the time `t` (an
    /// external's parameter, a moved group's velocity) with the numeric deck
    /// variables it names folded in; any other name is an error at it.
    pub(super) fn position_expression(&self, token: &Token) -> Result<DeckExpr, InputError> {
        let mut expr = DeckExpr::parse(std::slice::from_ref(token))?;
        for (r, span) in expr.expr.refs() {
            let known = matches!(r, Ref::Name("x" | "y" | "z" | "t"));
            if let (Ref::Name(name), false) = (r, known) {
                self.vars.number(name).map_err(|message| expr.error(&ExprError { span, message }))?;
            }
        }
        expr.expr = expr.expr.substitute(&|name| self.vars.number(name).ok().filter(|_| !matches!(name, "x" | "y" | "z" | "t")));
        Ok(expr)
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
            let x = self.initial.positions[m as usize];
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
    pub(super) fn at_particle(&self, expr: &DeckExpr, e: &ExprError, m: u32) -> InputError {
        let mut located = expr.error(e);
        let id = self.model.as_ref().expect("built").ids[m as usize];
        located.message = format!("at particle {id} (x = {}) and t = 0: {}", self.initial.positions[m as usize], located.message);
        located
    }
}
