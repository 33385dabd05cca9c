//! The plumbing between each interaction type's own LAMMPS translation
//! ([`Interaction::lammps`](crate::interactions::Interaction::lammps), in its
//! file under `src/interactions/`) and the script writer: the form each kind
//! of term takes, and the refusal when an interaction has no translation.
//! Nothing here knows an interaction by name.

use crate::expr::Ref;
use crate::forcefield::TermType;
use crate::interactions::lammps::{LammpsStyle, LammpsTerm, Moving};
use crate::interactions::Law;
use crate::system::External;

use super::formula;

/// A bonded style: the sub-style name and the coefficients after it.
#[derive(Clone, Debug, PartialEq)]
pub struct Styled {
    pub style: &'static str,
    pub coeffs: String,
}

/// A pair style instance: style, coefficients (including the cutoff), and
/// whether the style's energy is shifted to zero at the cutoff.
#[derive(Clone, Debug, PartialEq)]
pub struct PairStyled {
    pub style: &'static str,
    pub coeffs: String,
    pub cutoff: f64,
    pub shift: bool,
}

pub(super) fn unsupported(term: &TermType) -> String {
    format!(
        "{} `{}` uses `{}`, which LAMMPS cannot express",
        term.interaction.kind().with_article(),
        term.label.text,
        term.interaction.name()
    )
}

/// The translation of a bond, angle or pair term (no box, no expressions).
fn translate(term: &TermType) -> Option<Result<LammpsStyle, String>> {
    let view =
        LammpsTerm { params: &term.params, label: &term.label.text, box_lengths: [0.0; 3], periodic: [false; 3], moving: Moving::Fixed };
    term.interaction.lammps(&view)
}

/// The `bond_style` or `angle_style` sub-style and coefficients of a bond or angle type.
pub fn bonded(term: &TermType) -> Result<Styled, String> {
    match translate(term) {
        Some(Ok(LammpsStyle::Bonded { style, coeffs })) => Ok(Styled { style, coeffs }),
        Some(Err(e)) => Err(e),
        _ => Err(unsupported(term)),
    }
}

/// The `pair_style` instance and `pair_coeff` values of a pair rule.
pub fn pair(term: &TermType) -> Result<PairStyled, String> {
    let Law::Radial { range, .. } = term.interaction.law() else { return Err(unsupported(term)) };
    match translate(term) {
        Some(Ok(LammpsStyle::Pair { style, coeffs, shift })) => Ok(PairStyled { style, coeffs, cutoff: range(&term.params), shift }),
        Some(Err(e)) => Err(e),
        _ => Err(unsupported(term)),
    }
}

/// How an external is written: a fix, or `fix addforce` with atom-style
/// variables ([`LammpsStyle`] has the meaning of each).
pub enum ExternalStyle {
    Fix { args: String, variable: Option<String> },
    ParameterVariables,
    ExpressionVariables,
}

/// An external's translation: `lengths` and `periodic` describe the box;
/// `variable` names the equal-style variable a moving wall's face would get.
/// Expression parameters other than those the translation takes are an
/// error that says which LAMMPS takes.
pub fn external(external: &External, lengths: [f64; 3], periodic: [bool; 3], variable: &str) -> Result<ExternalStyle, String> {
    let term = &external.term;
    let moving = match &external.expressions[..] {
        [] => Moving::Fixed,
        [(index, expr)] if expr.refs().iter().all(|(r, _)| *r == Ref::Name("t")) => {
            Moving::Time { index: *index, formula: formula::lammps_formula(expr), variable }
        }
        _ => Moving::Other,
    };
    let expressions = !matches!(moving, Moving::Fixed);
    let view = LammpsTerm { params: &term.params, label: &term.label.text, box_lengths: lengths, periodic, moving };
    match term.interaction.lammps(&view) {
        Some(Ok(LammpsStyle::Fix { variable: None, .. })) | None if expressions => Err(format!(
            "external `{}`: expression parameters of `{}` are not exported (LAMMPS takes a wall's `d` as a formula of t, and a `field` as \
             `fix addforce` with atom-style variables)",
            term.label.text,
            term.interaction.name()
        )),
        Some(Ok(LammpsStyle::Fix { args, variable })) => Ok(ExternalStyle::Fix { args, variable }),
        Some(Ok(LammpsStyle::ParameterVariables)) => Ok(ExternalStyle::ParameterVariables),
        Some(Ok(LammpsStyle::ExpressionVariables)) => Ok(ExternalStyle::ExpressionVariables),
        Some(Err(e)) => Err(e),
        _ => Err(unsupported(term)),
    }
}
