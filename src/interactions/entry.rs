//! The documented registry entry that interaction types
//! ([`super::Interaction`]) and kinetic rules (`kinetics::KineticRule`) both
//! are: a name, a one-line summary, a Markdown page with the entry's physics
//! and references, and a parameter schema. `cellmd list NAME` prints
//! [`documentation`] of either kind of entry, and the force-field parser
//! checks `name value` pairs against [`Entry::params`] for both.
//!
//! The schema is a list of [`ParamSpec`]s (name, unit, allowed range with
//! its [`Bound`]s, default, doc), defined here for both registries.
//!
//! [`entry!`] implements the trait for a unit struct; the registries' own
//! macros (`interaction!`, `kinetic_rule!`) call it and add what their kind
//! of entry has beyond it (a law, an effect).

use crate::units::{Dim, UnitSystem};

/// An entry of a registry (an interaction type or a kinetic rule).
pub trait Entry: Sync + Send {
    /// Force-field keyword and registry name (snake_case), also the stem of
    /// the entry's `.rs` and `.md` files.
    fn name(&self) -> &'static str;
    /// What the entry is, in the title of its page: its interaction kind's
    /// keyword (`bond`, `pair`, …) or `kinetic rule`.
    fn category(&self) -> &'static str;
    /// One line for `cellmd list`.
    fn summary(&self) -> &'static str;
    /// The entry's Markdown (the `.md` beside its file), with the headings its
    /// registry requires; the parameter table is generated from the schema.
    fn doc(&self) -> &'static str;
    /// The parameter schema, in the order values reach the evaluator.
    fn params(&self) -> &'static [ParamSpec];
    /// Checks relations between parameters beyond per-parameter ranges.
    fn validate(&self, _params: &[f64]) -> Result<(), String> {
        Ok(())
    }
}

/// Full documentation page of an entry (what `cellmd list NAME` prints):
/// title with its category, summary, the `## Parameters` table (units of
/// `units`, generated from the schema), then the entry's own Markdown.
pub fn documentation(entry: &dyn Entry, units: UnitSystem) -> String {
    let (name, category, summary) = (entry.name(), entry.category(), entry.summary());
    let mut page = format!(
        "# {name} ({category})\n\n{summary}\n\n## Parameters\n\n| name | unit | allowed | default | meaning |\n|---|---|---|---|---|\n"
    );
    for p in entry.params() {
        let default = p.default.map_or("required".to_string(), |d| d.to_string());
        page += &format!("| `{}` | {} | {} | {} | {} |\n", p.name, units.label(p.dim), p.range_text(), default, p.doc);
    }
    page += "\n";
    page += entry.doc();
    page
}

/// Implements [`Entry`] for a unit struct it declares: its name (the stem of
/// the `.md` beside the invoking file, which becomes [`Entry::doc`]), its
/// category, its summary, the invoking module's `PARAMS` schema, and
/// optionally a `validate` function.
macro_rules! entry {
    ($ty:ident, $name:literal, $category:expr, $summary:literal $(, validate = $validate:path)?) => {
        pub struct $ty;

        impl $crate::interactions::Entry for $ty {
            fn name(&self) -> &'static str {
                $name
            }
            fn category(&self) -> &'static str {
                $category
            }
            fn summary(&self) -> &'static str {
                $summary
            }
            fn doc(&self) -> &'static str {
                include_str!(concat!($name, ".md"))
            }
            fn params(&self) -> &'static [$crate::interactions::ParamSpec] {
                &PARAMS
            }
            $(fn validate(&self, params: &[f64]) -> Result<(), String> {
                $validate(params)
            })?
        }
    };
}
pub(crate) use entry;

/// Inclusive/exclusive numeric bound of a parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    None,
    Inclusive(f64),
    Exclusive(f64),
}

/// One named, documented parameter of an interaction type.
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    pub name: &'static str,
    pub dim: Dim,
    pub min: Bound,
    pub max: Bound,
    /// `None` means the parameter is required.
    pub default: Option<f64>,
    pub doc: &'static str,
}

impl ParamSpec {
    /// A required parameter with no bounds; refine with the builder methods.
    pub const fn new(name: &'static str, dim: Dim, doc: &'static str) -> Self {
        Self { name, dim, min: Bound::None, max: Bound::None, default: None, doc }
    }
    pub const fn positive(mut self) -> Self {
        self.min = Bound::Exclusive(0.0);
        self
    }
    pub const fn non_negative(mut self) -> Self {
        self.min = Bound::Inclusive(0.0);
        self
    }
    pub const fn at_most(mut self, max: f64) -> Self {
        self.max = Bound::Inclusive(max);
        self
    }
    pub const fn below(mut self, max: f64) -> Self {
        self.max = Bound::Exclusive(max);
        self
    }
    pub const fn default(mut self, value: f64) -> Self {
        self.default = Some(value);
        self
    }

    /// Checks a value against the range; the error says what was expected.
    pub fn check(&self, value: f64) -> Result<(), String> {
        if !value.is_finite() {
            return Err(format!("a finite number for `{}`, found {value}", self.name));
        }
        let low_ok = match self.min {
            Bound::None => true,
            Bound::Inclusive(m) => value >= m,
            Bound::Exclusive(m) => value > m,
        };
        let high_ok = match self.max {
            Bound::None => true,
            Bound::Inclusive(m) => value <= m,
            Bound::Exclusive(m) => value < m,
        };
        if low_ok && high_ok {
            Ok(())
        } else {
            Err(format!("`{}` {}, found {value}", self.name, self.range_text()))
        }
    }

    /// The allowed range in words, e.g. `> 0` or `in [0, 1]`.
    pub fn range_text(&self) -> String {
        // (bracket, comparison, value) of each side that is bounded.
        let lower = match self.min {
            Bound::None => None,
            Bound::Inclusive(a) => Some(('[', ">=", a)),
            Bound::Exclusive(a) => Some(('(', ">", a)),
        };
        let upper = match self.max {
            Bound::None => None,
            Bound::Inclusive(b) => Some((']', "<=", b)),
            Bound::Exclusive(b) => Some((')', "<", b)),
        };
        match (lower, upper) {
            (None, None) => "any finite value".into(),
            (Some((_, op, v)), None) | (None, Some((_, op, v))) => format!("{op} {v}"),
            (Some((l, _, a)), Some((r, _, b))) => format!("in {l}{a}, {b}{r}"),
        }
    }
}
