//! What `coeff` and `ramp` change: a term of the working model named by
//! `bond NAME`, `angle NAME`, `pair A B`, `body TYPE LAW` or `external NAME`,
//! and one parameter of its law, checked against the law's schema.

use super::{expect_len, Validator};
use crate::deck::plan::CoeffTarget;
use crate::forcefield::{check_param, param_position, TermType};
use crate::input::{InputError, Token};
use crate::interactions::Kind;

impl Validator {
    /// The terms `s[1..]` names and the index of the first token after the
    /// name (`bond NAME`, `angle NAME`, `pair A B` (every rule between the two
    /// types), `body TYPE LAW`, `external NAME`).
    pub(super) fn coeff_targets(&mut self, s: &[Token], usage: &str) -> Result<(Vec<CoeffTarget>, usize), InputError> {
        let model = self.model(&s[0])?;
        match s[1].text.as_str() {
            "bond" | "angle" => {
                let missing = || s[2].error(format!("found {} type `{}`, expected one defined in the force field", s[1].text, s[2].text));
                let named = |t: &TermType| t.label.text == s[2].text;
                let target = match Kind::from_keyword(&s[1].text) {
                    Some(Kind::Bond) => CoeffTarget::BondType(model.bond_types.iter().position(|t| named(t)).ok_or_else(missing)?),
                    _ => CoeffTarget::AngleType(model.angle_types.iter().position(|t| named(t)).ok_or_else(missing)?),
                };
                Ok((vec![target], 3))
            }
            "pair" => {
                expect_len(s, 4..=usize::MAX, usage)?;
                let (a, b) = (&s[2].text, &s[3].text);
                let rules: Vec<CoeffTarget> = (0..model.pair_rules.len())
                    .filter(|&k| {
                        let (ta, tb) = model.pair_rule_types[k];
                        let (ra, rb) = (&model.type_names[ta as usize], &model.type_names[tb as usize]);
                        (ra == a && rb == b) || (ra == b && rb == a)
                    })
                    .map(CoeffTarget::PairRule)
                    .collect();
                if rules.is_empty() {
                    return Err(s[2].error(format!(
                        "no pair rule between `{a}` and `{b}`; expected a type pair with a `pair` line in the force field"
                    )));
                }
                Ok((rules, 4))
            }
            "body" => {
                expect_len(s, 4..=usize::MAX, usage)?;
                let body_type = model.body_type_names.iter().position(|n| *n == s[2].text).ok_or_else(|| {
                    s[2].error(format!(
                        "found body type `{}`, expected one that `body` lines of the force field name ({})",
                        s[2].text,
                        model.body_type_names.join(", ")
                    ))
                })?;
                let of_type: Vec<usize> = (0..model.body_rules.len()).filter(|&k| model.body_rule_type[k] as usize == body_type).collect();
                let rules: Vec<CoeffTarget> = of_type
                    .iter()
                    .filter(|&&k| model.body_rules[k].interaction.name() == s[3].text)
                    .map(|&k| CoeffTarget::BodyRule(k))
                    .collect();
                if rules.is_empty() {
                    let laws: Vec<&str> = of_type.iter().map(|&k| model.body_rules[k].interaction.name()).collect();
                    return Err(s[3].error(format!(
                        "body type `{}` has no `{}` term; expected the law of one of its `body` lines: {}",
                        s[2].text,
                        s[3].text,
                        laws.join(", ")
                    )));
                }
                Ok((rules, 4))
            }
            "external" => {
                if !model.externals.iter().any(|e| e.term.label.text == s[2].text) {
                    return Err(s[2].error(format!("found `{}`, expected the name of an active external", s[2].text)));
                }
                Ok((vec![CoeffTarget::External(s[2].text.clone())], 3))
            }
            other => Err(s[1].error(format!("found `{other}`, expected `bond`, `angle`, `pair`, `body` or `external`"))),
        }
    }

    /// The index of the parameter `name` of `target`'s law. A bond type's
    /// `r0` is refused where bonds have their own rest lengths (from the
    /// topology or `reset_rest`), and a parameter already ramped over the
    /// next run is refused.
    pub(super) fn target_param(&mut self, target: &CoeffTarget, name: &Token) -> Result<usize, InputError> {
        let model = self.model(name)?;
        let mut own_rest = 0usize;
        let mut rest_index = None;
        if let CoeffTarget::BondType(k) = target {
            own_rest = (0..model.bond_rest.len()).filter(|&b| model.bond_type[b] as usize == *k && model.bond_rest[b].is_some()).count();
            rest_index = model.bond_kinetics[*k].rest_index;
        }
        let term = target.term(model);
        let (label, interaction) = (term.label.text.clone(), term.interaction);
        let index = param_position(interaction.params(), interaction.name(), name)?;
        if rest_index == Some(index) {
            if let Some(reset) = self.protocols.reset_by(target) {
                return Err(name.error(format!(
                    "bond type `{label}` took its bonds' rest lengths from the geometry (`reset_rest` on line {reset}), so its `r0` no longer applies; expected a parameter other than `r0`"
                )));
            }
            if own_rest > 0 {
                return Err(name.error(format!(
                    "bond type `{label}` has {own_rest} bond{} with its own rest length in the topology, which `coeff` cannot change; expected a parameter other than `r0`",
                    if own_rest == 1 { "" } else { "s" }
                )));
            }
        }
        if self.protocols.is_ramped(target, index) {
            return Err(name.error(format!(
                "`{}` of `{label}` is already ramped over the next `run`; expected one `ramp` or `coeff` per parameter before it",
                name.text
            )));
        }
        Ok(index)
    }

    /// Checks `value` for parameter `param` of `target` (its schema's range
    /// and the law's own checks with the other parameters in force) and sets
    /// it in the working model. `at` is the value's token.
    pub(super) fn set_target_param(&mut self, target: &CoeffTarget, param: usize, value: f64, at: &Token) -> Result<(), InputError> {
        let model = self.model(at)?;
        check_param(&target.term(model).interaction.params()[param], value, at)?;
        target.set(model, param, value);
        let term = target.term(model);
        term.interaction
            .validate(&term.params)
            .map_err(|e| at.error(format!("invalid `{}` parameters: expected {e}", term.interaction.name())))
    }

    /// The cutoff of a pair rule's law with its current parameters (None
    /// for other targets).
    pub(super) fn pair_cutoff(&mut self, target: &CoeffTarget, at: &Token) -> Result<Option<f64>, InputError> {
        let CoeffTarget::PairRule(k) = target else { return Ok(None) };
        let term = &self.model(at)?.pair_rules[*k];
        Ok(Some((term.law.range)(&term.params)))
    }
}
