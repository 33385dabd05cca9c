//! `name value` parameter lists checked against an interaction's schema.

use crate::input::{parse_f64, InputError, Token};
use crate::interactions::{lookup, Interaction, Kind, REGISTRY};
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
        let names: Vec<&str> = REGISTRY.iter().filter(|i| i.kind() == kind).map(|i| i.name()).collect();
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
    let specs = interaction.params();
    let mut values: Vec<Option<f64>> = vec![None; specs.len()];
    let mut pairs = tokens.chunks(2);
    for pair in &mut pairs {
        let name = &pair[0];
        let index = specs.iter().position(|s| s.name == name.text).ok_or_else(|| {
            let names: Vec<&str> = specs.iter().map(|s| s.name).collect();
            name.error(format!(
                "found parameter `{}`, expected one of `{}`'s parameters: {}",
                name.text,
                interaction.name(),
                names.join(", ")
            ))
        })?;
        let Some(value_token) = pair.get(1) else {
            return Err(name.error(format!("parameter `{}` has no value; expected `{} VALUE`", name.text, name.text)));
        };
        if values[index].is_some() {
            return Err(name.error(format!("parameter `{}` is given twice; expected it once", name.text)));
        }
        let spec = &specs[index];
        let value = parse_f64(value_token, &format!("a value for `{}` in {}", spec.name, units.label(spec.dim)))?;
        spec.check(value).map_err(|e| value_token.error(format!("expected {e}")))?;
        values[index] = Some(value);
    }
    let mut params = Vec::with_capacity(specs.len());
    for (spec, value) in specs.iter().zip(values) {
        match value.or(spec.default) {
            Some(v) => params.push(v),
            None => {
                return Err(interaction_token.error(format!(
                    "`{}` needs parameter `{}` ({}, {}): expected `{} VALUE`",
                    interaction.name(),
                    spec.name,
                    spec.doc,
                    units.label(spec.dim),
                    spec.name
                )))
            }
        }
    }
    interaction
        .validate(&params)
        .map_err(|e| interaction_token.error(format!("invalid `{}` parameters: expected {e}", interaction.name())))?;
    Ok(TermType { label: label.clone(), interaction, params })
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
