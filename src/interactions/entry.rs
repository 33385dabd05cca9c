//! The documented registry entry that interaction types
//! ([`super::Interaction`]) and kinetic rules (`kinetics::KineticRule`) both
//! are: a name, a one-line summary, a Markdown page with the entry's physics
//! and references, and a parameter schema. `cellmd list NAME` prints
//! [`documentation`] of either kind of entry, and the force-field parser
//! checks `name value` pairs against [`Entry::params`] for both.
//!
//! [`entry!`] implements the trait for a unit struct; the registries' own
//! macros (`interaction!`, `kinetic_rule!`) call it and add what their kind
//! of entry has beyond it (a law, an effect).

use super::ParamSpec;
use crate::units::UnitSystem;

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
