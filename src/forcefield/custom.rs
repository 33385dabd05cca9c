//! `custom` force-field terms: `KIND LABEL… custom "EXPRESSION" [name value[unit]]...`.
//!
//! The expression is the energy (grammar, variables and functions:
//! `cellmd list custom`); each `name value` pair declares a parameter the
//! expression reads. A value may carry a unit suffix, `theta0 180deg`,
//! `r0 200nm`, `k 40pN/µm`: it is converted into the deck's unit system
//! (degrees into radians) and the parameter takes that unit's dimension;
//! without a suffix it is a number in the deck's units. A pair needs
//! `cutoff VALUE` (length): E ≡ 0 beyond it. Errors inside the expression
//! point at their column within the quoted string.

use crate::expr::{Expr, Span};
use crate::input::{parse_f64, InputError, Token};
use crate::interactions::custom::{CustomError, CustomLaw, Declared, CUTOFF};
use crate::interactions::Kind;
use crate::units::{Dim, UnitSystem};

use super::TermType;

/// Every dimension, for matching a unit suffix against the system's labels.
const DIMS: [Dim; 19] = [
    Dim::Dimensionless,
    Dim::Length,
    Dim::Time,
    Dim::Force,
    Dim::Energy,
    Dim::Stiffness,
    Dim::BendingModulus,
    Dim::AngularStiffness,
    Dim::Degrees,
    Dim::Drag,
    Dim::Viscosity,
    Dim::Pressure,
    Dim::Temperature,
    Dim::Tension,
    Dim::Rate,
    Dim::Velocity,
    Dim::Area,
    Dim::Volume,
    Dim::Curvature,
];

/// Scaled units of the `cell` system beyond its own labels: (suffix, factor, dimension).
const SCALED: [(&str, f64, Dim); 6] = [
    ("nm", 1e-3, Dim::Length),
    ("mm", 1e3, Dim::Length),
    ("ms", 1e-3, Dim::Time),
    ("nN", 1e3, Dim::Force),
    ("fN", 1e-3, Dim::Force),
    ("kPa", 1e3, Dim::Pressure),
];

/// A unit suffix's factor into the deck's units and its dimension.
fn unit(suffix: &str, units: UnitSystem) -> Option<(f64, Dim)> {
    let normal = suffix.replace("um", "µm").replace('*', "·");
    match normal.as_str() {
        "" | "rad" => return Some((1.0, Dim::Dimensionless)),
        "deg" => return Some((std::f64::consts::PI / 180.0, Dim::Dimensionless)),
        _ => {}
    }
    if let Some(dim) = DIMS.iter().copied().filter(|d| !matches!(d, Dim::Dimensionless | Dim::Degrees)).find(|d| units.label(*d) == normal)
    {
        return Some((1.0, dim));
    }
    SCALED.iter().find(|(s, _, _)| units == UnitSystem::Cell && *s == normal).map(|(_, f, d)| (*f, *d))
}

/// A value with an optional unit suffix, in the deck's units.
fn value_with_unit(token: &Token, name: &str, units: UnitSystem) -> Result<(f64, Dim), InputError> {
    let text = token.text.as_str();
    let split = (1..=text.len()).rev().filter(|&k| text.is_char_boundary(k)).find(|&k| text[..k].parse::<f64>().is_ok());
    let Some(split) = split.filter(|&k| !text[..k].to_ascii_lowercase().contains("inf") && !text[..k].to_ascii_lowercase().contains("nan"))
    else {
        parse_f64(token, &format!("a value for `{name}`"))?;
        return Err(token.error(format!("found `{text}`, expected a value for `{name}` (a number with an optional unit)")));
    };
    let value: f64 = text[..split].parse().expect("checked");
    let suffix = &text[split..];
    let (factor, dim) = unit(suffix, units).ok_or_else(|| {
        token.error_within(
            split,
            format!(
                "found unit `{suffix}`, expected a unit of the deck's system ({}, {}, {}, {}, …), deg or rad",
                units.label(Dim::Length),
                units.label(Dim::Force),
                units.label(Dim::Energy),
                units.label(Dim::Stiffness)
            ),
        )
    })?;
    let converted = value * factor;
    if !converted.is_finite() {
        return Err(token.error(format!("found `{text}`, expected a finite value for `{name}`")));
    }
    Ok((converted, dim))
}

/// Parses `tokens` (the quoted expression, then `name value` pairs) into a
/// custom term of `kind`; `custom` is the `custom` keyword's token.
pub fn parse_custom(label: &Token, custom: &Token, tokens: &[Token], kind: Kind, units: UnitSystem) -> Result<TermType, InputError> {
    build(label, custom, tokens, kind, units).map(|(term, _)| term)
}

/// A deck's `external NAME GROUP custom "EXPR" ...`: the term, and the
/// parameter expressions the system's `External` evaluates at each
/// step (the time slot, `t`, when the expression reads it).
pub fn parse_custom_external(
    label: &Token,
    custom: &Token,
    tokens: &[Token],
    units: UnitSystem,
) -> Result<(TermType, Vec<(usize, Expr)>), InputError> {
    let (term, law) = build(label, custom, tokens, Kind::External, units)?;
    let span = Span { start: 0, end: 1 };
    Ok((term, law.time_slot().map(|k| (k, Expr::Name("t".into(), span))).into_iter().collect()))
}

fn build(
    label: &Token,
    custom: &Token,
    tokens: &[Token],
    kind: Kind,
    units: UnitSystem,
) -> Result<(TermType, &'static CustomLaw), InputError> {
    let Some(text) = tokens.first() else {
        return Err(custom.error(format!(
            "expected `custom \"EXPRESSION\" [name value]...` after `{}`; `cellmd list custom` has the grammar",
            custom.text
        )));
    };
    let pairs = &tokens[1..];
    let mut declared = Vec::new();
    let mut values = Vec::new();
    let mut names: Vec<&Token> = Vec::new();
    let mut cutoff = None;
    for pair in pairs.chunks(2) {
        let name = &pair[0];
        let Some(value) = pair.get(1) else {
            return Err(name.error(format!("parameter `{}` has no value; expected `{} VALUE`", name.text, name.text)));
        };
        if !name.text.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            || !name.text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        {
            return Err(name.error(format!("found `{}`, expected a parameter name (letters, digits, `_`)", name.text)));
        }
        let (v, dim) = value_with_unit(value, &name.text, units)?;
        if kind == Kind::Pair && name.text == CUTOFF {
            if cutoff.is_some() {
                return Err(name.error("`cutoff` is given twice; expected it once"));
            }
            if v <= 0.0 {
                return Err(value.error(format!("expected `cutoff` > 0, found {v}")));
            }
            cutoff = Some((v, name));
            continue;
        }
        declared.push(Declared { name: name.text.clone(), dim });
        values.push(v);
        names.push(name);
    }
    if kind == Kind::Pair {
        let Some((v, name)) = cutoff else {
            return Err(custom.error("a custom pair needs `cutoff VALUE` (length): expected `cutoff VALUE`"));
        };
        declared.insert(0, Declared { name: CUTOFF.into(), dim: Dim::Length });
        values.insert(0, v);
        names.insert(0, name);
    }
    let law = CustomLaw::new(kind, &text.text, &declared).map_err(|e| match e {
        CustomError::Expression(e) => text.error_within(e.span.start, e.message),
        CustomError::Parameter { index, message } => names[index].error(message),
    })?;
    Ok((TermType { label: label.clone(), interaction: law, params: law.params(&values) }, law))
}
