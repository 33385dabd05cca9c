//! `bind` lines of a force-field file, as parsed and as resolved against the
//! model's type names:
//!
//! ```text
//! bind TYPE_A TYPE_B BONDTYPE k_on K capture R [max_bonds N] [partner random|nearest] [between any|bodies]
//! ```
//!
//! What a rule does during a run (candidate pairs, acceptance order, bonds
//! formed and rebound) is the formation step of the kinetics engine, whose
//! module doc (`kinetics_engine::formation`) describes it.

use crate::input::{parse_u64, InputError, Token};
use crate::interactions::ParamSpec;
use crate::units::{Dim, UnitSystem};

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("k_on", Dim::Rate, "formation rate of a pair within capture").non_negative(),
    ParamSpec::new("capture", Dim::Length, "capture radius").positive(),
];

/// A resolved `bind` line.
#[derive(Clone, Debug)]
pub struct BindRule {
    pub type_a: u32,
    pub type_b: u32,
    pub bond_type: u32,
    pub k_on: f64,
    pub capture: f64,
    pub max_bonds: u32,
    /// Only mutual-nearest pairs are candidates.
    pub nearest: bool,
    /// Only particles of two different bodies bind.
    pub between_bodies: bool,
}

/// The body of a particle outside every body (as `Model::body_of_particles` gives it).
pub const NO_BODY: u32 = u32::MAX;

impl BindRule {
    /// Whether the rule pairs a particle of type `ti` with one of type `tj` (either order).
    pub fn joins_types(&self, ti: u32, tj: u32) -> bool {
        (self.type_a, self.type_b) == (ti, tj) || (self.type_a, self.type_b) == (tj, ti)
    }

    /// Whether particles of bodies `bi` and `bj` ([`NO_BODY`]: none) may bind
    /// under the rule: any two, or with `between bodies` two of different bodies.
    pub fn joins_bodies(&self, bi: u32, bj: u32) -> bool {
        !self.between_bodies || (bi != NO_BODY && bj != NO_BODY && bi != bj)
    }
}

/// A `bind` line as parsed (names resolved later against the model).
#[derive(Clone, Debug)]
pub struct BindLine {
    pub type_a: Token,
    pub type_b: Token,
    pub bond_type: Token,
    pub k_on: f64,
    pub capture: f64,
    pub max_bonds: u32,
    pub nearest: bool,
    pub between_bodies: bool,
}

/// Parses `bind A B BONDTYPE k_on K capture R [max_bonds N] [partner random|nearest]`
/// (tokens after `bind`).
pub fn parse_bind(keyword: &Token, t: &[Token], units: UnitSystem) -> Result<BindLine, InputError> {
    const USAGE: &str = "bind TYPE_A TYPE_B BONDTYPE k_on K capture R [max_bonds N] [partner random|nearest] [between any|bodies]";
    if t.len() < 3 {
        return Err(keyword.error(format!("expected `{USAGE}`")));
    }
    let (mut max_bonds, mut nearest, mut between_bodies) = (1, false, false);
    let mut values = Vec::new();
    for pair in t[3..].chunks(2) {
        let Some(value) = pair.get(1) else {
            return Err(pair[0].error(format!("`{}` has no value; expected `{USAGE}`", pair[0].text)));
        };
        match pair[0].text.as_str() {
            "max_bonds" => {
                max_bonds = parse_u64(value, "a maximum number of bonds per particle")? as u32;
                if max_bonds == 0 {
                    return Err(value.error("found 0, expected `max_bonds` >= 1"));
                }
            }
            "partner" => {
                nearest = match value.text.as_str() {
                    "random" => false,
                    "nearest" => true,
                    other => return Err(value.error(format!("found `{other}`, expected `random` or `nearest`"))),
                }
            }
            "between" => {
                between_bodies = match value.text.as_str() {
                    "any" => false,
                    "bodies" => true,
                    other => {
                        return Err(value.error(format!("found `{other}`, expected `any` or `bodies` (particles of different bodies)")))
                    }
                }
            }
            _ => values.extend_from_slice(pair),
        }
    }
    let values = super::parse_values(&PARAMS, "bind", keyword, &values, units)?;
    Ok(BindLine {
        type_a: t[0].clone(),
        type_b: t[1].clone(),
        bond_type: t[2].clone(),
        k_on: values[0],
        capture: values[1],
        max_bonds,
        nearest,
        between_bodies,
    })
}
