//! `name value` parameter lists checked against an interaction's schema.

use crate::input::{parse_f64, InputError, Token};
use crate::interactions::{lookup, Interaction, Kind, KindLaw, ParamSpec, REGISTRY};
use crate::kinetics::{lookup_rule, RuleUse, RULES};
use crate::units::UnitSystem;

/// A named, parameterised use of an interaction type (a bond type, an angle
/// type, a pair rule or an external field).
#[derive(Clone)]
pub struct TermType {
    /// The user's label (bond/angle type name, `A-B` for pairs, the external's name).
    pub label: Token,
    pub interaction: &'static dyn Interaction,
    /// Values in schema order.
    pub params: Vec<f64>,
}

impl std::fmt::Debug for TermType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {} {:?}", self.label.text, self.interaction.name(), self.params)
    }
}

/// A term type of one kind with its law taken out at build time
/// ([`KindLaw`]): `law` is what the loops over this kind evaluate. It
/// dereferences to its [`TermType`] (label, interaction, parameters); the
/// parameters may change (`coeff`, ramps, drives), the interaction may not.
#[derive(Clone, Debug)]
pub struct Typed<L> {
    term: TermType,
    pub law: L,
}

impl<L: KindLaw> Typed<L> {
    /// `term` with its law, or `term` back when its law is not of family `L`.
    pub fn new(term: TermType) -> Result<Self, TermType> {
        match L::from_law(term.interaction.law()) {
            Some(law) => Ok(Typed { term, law }),
            None => Err(term),
        }
    }

    /// The term type, for code that reads terms of every kind.
    pub fn term(&self) -> &TermType {
        &self.term
    }

    /// The parameters, for the edits that change them.
    pub fn params_mut(&mut self) -> &mut Vec<f64> {
        &mut self.term.params
    }
}

impl<L> std::ops::Deref for Typed<L> {
    type Target = TermType;
    fn deref(&self) -> &TermType {
        &self.term
    }
}

/// Resolves `interaction_token` against the registry (it must be of `kind`)
/// and parses `tokens` as its `name value` pairs, filling defaults.
pub fn parse_params(
    label: &Token,
    interaction_token: &Token,
    tokens: &[Token],
    kind: Kind,
    units: UnitSystem,
) -> Result<TermType, InputError> {
    let interaction = lookup(&interaction_token.text).ok_or_else(|| {
        // `custom` (registered as a body term) takes every kind but contact and tetra.
        let offered = |i: &&&dyn Interaction| i.kind() == kind || (i.name() == "custom" && !matches!(kind, Kind::Contact | Kind::Tetra));
        let names: Vec<&str> = REGISTRY.iter().filter(offered).map(|i| i.name()).collect();
        interaction_token.error(format!(
            "found `{}`, expected a registered {} interaction: {}",
            interaction_token.text,
            kind.keyword(),
            names.join(", ")
        ))
    })?;
    if interaction.kind() != kind {
        return Err(interaction_token.error(format!(
            "`{}` is {} interaction, expected {} interaction here",
            interaction.name(),
            interaction.kind().with_article(),
            kind.with_article()
        )));
    }
    let params = parse_values(interaction.params(), interaction.name(), interaction_token, tokens, units)?;
    interaction
        .validate(&params)
        .map_err(|e| interaction_token.error(format!("invalid `{}` parameters: expected {e}", interaction.name())))?;
    Ok(TermType { label: label.clone(), interaction, params })
}

/// Parses `name value` pairs against a schema (in schema order, defaults
/// filled); `owner` names the interaction or rule in messages and
/// `owner_token` is where a missing parameter is reported.
pub fn parse_values(
    specs: &[ParamSpec],
    owner: &str,
    owner_token: &Token,
    tokens: &[Token],
    units: UnitSystem,
) -> Result<Vec<f64>, InputError> {
    let mut values: Vec<Option<f64>> = vec![None; specs.len()];
    for pair in tokens.chunks(2) {
        let name = &pair[0];
        let index = param_position(specs, owner, name)?;
        let Some(value_token) = pair.get(1) else {
            return Err(name.error(format!("parameter `{}` has no value; expected `{} VALUE`", name.text, name.text)));
        };
        if values[index].is_some() {
            return Err(name.error(format!("parameter `{}` is given twice; expected it once", name.text)));
        }
        values[index] = Some(param_value(&specs[index], value_token, units)?);
    }
    specs
        .iter()
        .zip(values)
        .map(|(spec, value)| {
            value.or(spec.default).ok_or_else(|| {
                owner_token.error(format!(
                    "`{owner}` needs parameter `{}` ({}, {}): expected `{} VALUE`",
                    spec.name,
                    spec.doc,
                    units.label(spec.dim),
                    spec.name
                ))
            })
        })
        .collect()
}

/// The index of the parameter `name` in a schema; `owner` names the
/// interaction or rule in the message.
pub fn param_position(specs: &[ParamSpec], owner: &str, name: &Token) -> Result<usize, InputError> {
    specs.iter().position(|s| s.name == name.text).ok_or_else(|| {
        let names: Vec<&str> = specs.iter().map(|s| s.name).collect();
        name.error(format!("found parameter `{}`, expected one of `{owner}`'s parameters: {}", name.text, names.join(", ")))
    })
}

/// A parameter's value: `token` as a number in the parameter's unit,
/// within its schema's range.
pub fn param_value(spec: &ParamSpec, token: &Token, units: UnitSystem) -> Result<f64, InputError> {
    let value = parse_f64(token, &format!("a value for `{}` in {}", spec.name, units.label(spec.dim)))?;
    check_param(spec, value, token)?;
    Ok(value)
}

/// Checks `value` against its parameter's range (`at`: where it was given).
pub fn check_param(spec: &ParamSpec, value: f64, at: &Token) -> Result<(), InputError> {
    spec.check(value).map_err(|e| at.error(format!("expected {e}")))
}

/// Parses the `kinetics RULE name value ...` clauses that follow a bond
/// type's law parameters. `tokens` starts at the first `kinetics`.
pub fn parse_kinetics(law: &TermType, tokens: &[Token], units: UnitSystem) -> Result<BondTypeKinetics, InputError> {
    let rest_index = crate::interactions::param_index(law.interaction, "r0");
    let mut rules = Vec::new();
    let starts: Vec<usize> = tokens.iter().enumerate().filter(|(_, t)| t.text == "kinetics").map(|(k, _)| k).collect();
    for (n, &start) in starts.iter().enumerate() {
        let end = starts.get(n + 1).copied().unwrap_or(tokens.len());
        let Some(rule_token) = tokens.get(start + 1).filter(|_| start + 1 < end) else {
            return Err(tokens[start].error("expected a kinetic rule name after `kinetics`"));
        };
        let rule = lookup_rule(&rule_token.text).ok_or_else(|| {
            let names: Vec<&str> = RULES.iter().map(|r| r.name()).collect();
            rule_token.error(format!("found `{}`, expected a registered kinetic rule: {}", rule_token.text, names.join(", ")))
        })?;
        if rule.needs_rest_length() && rest_index.is_none() {
            return Err(rule_token.error(format!(
                "`{}` changes the rest length, expected a bond law with a rest length `r0` (`{}` has none)",
                rule.name(),
                law.interaction.name()
            )));
        }
        let params = parse_values(rule.params(), rule.name(), rule_token, &tokens[start + 2..end], units)?;
        rule.validate(&params).map_err(|e| rule_token.error(format!("invalid `{}` parameters: expected {e}", rule.name())))?;
        rules.push(RuleUse { rule, params });
    }
    Ok(BondTypeKinetics { rules, rest_index })
}

/// The kinetic rules of a bond type.
#[derive(Clone, Debug, Default)]
pub struct BondTypeKinetics {
    pub rules: Vec<RuleUse>,
    /// Index of `r0` in the law's parameters, if it has one.
    pub rest_index: Option<usize>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::{lex, SourceFile};

    fn parse(line: &str) -> Result<TermType, String> {
        let s = lex(&SourceFile::new("f.ff", line)).unwrap().remove(0);
        parse_params(&s.tokens[0], &s.tokens[1], &s.tokens[2..], Kind::Bond, UnitSystem::Cell).map_err(|e| e.to_string())
    }

    #[test]
    fn schema_is_enforced() {
        assert_eq!(parse("s harmonic r0 0.1 k 4").unwrap().params, vec![4.0, 0.1]);
        assert_eq!(
            parse("s harmonic k 4").unwrap_err(),
            "f.ff:1:3: `harmonic` needs parameter `r0` (rest length, µm): expected `r0 VALUE`"
        );
        assert_eq!(
            parse("s harmonic k 4 r0 0.1 kk 2").unwrap_err(),
            "f.ff:1:23: found parameter `kk`, expected one of `harmonic`'s parameters: k, r0"
        );
        assert_eq!(parse("s harmonic k -4 r0 0.1").unwrap_err(), "f.ff:1:14: expected `k` >= 0, found -4");
        assert!(parse("s harmonic k nan r0 0.1").unwrap_err().contains("a finite number"));
        assert!(parse("s harmonic k 1 k 2 r0 1").unwrap_err().contains("given twice"));
        assert!(parse("s harmonic k").unwrap_err().contains("has no value"));
        assert!(parse("s nosuch k 1").unwrap_err().contains("expected a registered bond interaction: harmonic"));
    }
}
