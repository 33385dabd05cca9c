//! Force-dependent bond kinetics: stateful bonds that break, rebind, slide,
//! mature and yield according to the force they carry.
//!
//! A bond type combines a mechanical law (any registered bond interaction)
//! with zero or more **kinetic rules**, written after `kinetics` on its
//! force-field line:
//!
//! ```text
//! bond clutch harmonic k 1 r0 0.02 kinetics catch_slip kc0 10 xc 0.002 ks0 0.1 xs 0.001 kinetics rebind k_on 5 capture 0.05
//! ```
//!
//! Each bond then carries state (`system::BondState`): bound or not, its age
//! since formation, its current rest length and a stiffness scale. After every
//! force pass the engine (`kinetics_engine::Kinetics`) reads each bond's
//! tension F (= dE/dr, positive when stretched) and length, decides every
//! state change with counter-based random numbers keyed by (seed, step, bond
//! index), queues the events, and applies them together; the run loop then
//! recomputes the forces. A bond
//! survives a step at rate k(F) with the exact probability exp(−k·dt); when
//! k·dt > 0.1 the step is too coarse to resolve the bond's lifetime, and a
//! warning is printed once per bond type.
//!
//! Rules are registered in [`RULES`], one file each; like an interaction type
//! each is a documented registry [`Entry`] (name, summary, Markdown page,
//! schema: `cellmd list NAME`).
//!
//! A rule whose effect the GPU backend decides on the device
//! ([`Effect::gpu_form`]: unbinding, threshold breaking, rebinding) has its
//! WGSL evaluator beside it, `NAME.wgsl`, defining `NAME_SUFFIX` with the
//! suffix of its [`GpuForm`] (`slip_rate`, `threshold_beyond`,
//! `rebind_on_rate`). It reads its parameters by names generated from its
//! schema (`p[CATCH_SLIP_KC0]`), and the shader composer dispatches it by
//! its registry index, as interactions are (src/gpu/shader.rs): adding such a
//! rule is its `.rs`, `.md` and `.wgsl` and one line in [`RULES`].
//!
//! This folder is the registry only: what each rule is (parameters, effect,
//! documentation). The force-field parser reads rule names and parameters
//! here, so the registry sits below `forcefield`; the engine that applies the
//! rules every step reads the system and the neighbour list, which sit above
//! `forcefield`, so it is a folder of its own, `kinetics_engine`.

use crate::interactions::Entry;

mod cadherin;
mod catch_slip;
mod maturation;
mod motor;
mod plastic;
mod ratchet;
mod rebind;
mod slip;
mod threshold;

pub(crate) use self::threshold::deterministic_strain;

/// Every registered kinetic rule.
pub static RULES: &[&dyn KineticRule] = &[
    &slip::Slip,
    &catch_slip::CatchSlip,
    &cadherin::Cadherin,
    &threshold::Threshold,
    &rebind::Rebind,
    &maturation::Maturation,
    &plastic::Plastic,
    &motor::Motor,
    &ratchet::Ratchet,
];

/// The registry index of a rule (its place in [`RULES`]).
pub fn rule_index(rule: &dyn KineticRule) -> usize {
    RULES.iter().position(|r| r.name() == rule.name()).expect("a registered rule")
}

/// Looks a kinetic rule up by name.
pub fn lookup_rule(name: &str) -> Option<&'static dyn KineticRule> {
    RULES.iter().copied().find(|r| r.name() == name)
}

/// What a rule does to a bond, with its evaluator.
#[derive(Clone, Copy)]
pub enum Effect {
    /// A bound bond breaks at rate k_off(F, kT) (per time unit).
    Unbind(fn(&[f64], f64, f64) -> f64),
    /// Beyond its threshold a bound bond breaks at the returned rate
    /// (infinite: at once); `None` below it. Arguments: params, F, strain, and
    /// `u`, a uniform number in (0, 1) fixed per bond (its quenched disorder).
    Threshold(fn(&[f64], f64, f64, f64) -> Option<f64>),
    /// An unbound bond rebinds at rate k_on when its length is below the
    /// capture radius: returns (k_on, capture).
    Rebind(fn(&[f64]) -> (f64, f64)),
    /// The rest length changes at dL0/dt = v(F, kT) (length/time).
    RestLengthRate(fn(&[f64], f64, f64) -> f64),
    /// When |L − L0|/L0 exceeds the returned threshold, L0 becomes L.
    PlasticReset(fn(&[f64]) -> f64),
    /// Stiffness (energy and force) scale as a function of the bond's age.
    Maturation(fn(&[f64], f64) -> f64),
}

/// How the GPU backend decides a rule's effect: the WGSL function its
/// `NAME.wgsl` defines (`NAME_` + [`Self::suffix`]), with the signature of
/// its effect's evaluator in f32.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuForm {
    /// `fn NAME_rate(p: array<f32, 8>, f: f32, kt: f32) -> f32`: k_off(F, kT).
    Unbind = 1,
    /// `fn NAME_beyond(p: array<f32, 8>, force: f32, strain: f32, u: f32) -> Beyond`:
    /// whether the bond is beyond its threshold, and its break rate there (0: at once).
    Threshold = 2,
    /// `fn NAME_on_rate(p: array<f32, 8>) -> vec2<f32>`: (k_on, capture radius).
    Rebind = 3,
}

impl GpuForm {
    pub const ALL: [GpuForm; 3] = [GpuForm::Unbind, GpuForm::Threshold, GpuForm::Rebind];

    /// The evaluator's name after the rule's: `slip_rate`.
    pub fn suffix(self) -> &'static str {
        match self {
            GpuForm::Unbind => "rate",
            GpuForm::Threshold => "beyond",
            GpuForm::Rebind => "on_rate",
        }
    }
}

impl Effect {
    /// The device form of this effect, where the GPU backend decides it
    /// (None: rules with this effect keep a model's kinetics on the host).
    pub fn gpu_form(&self) -> Option<GpuForm> {
        match self {
            Effect::Unbind(_) => Some(GpuForm::Unbind),
            Effect::Threshold(_) => Some(GpuForm::Threshold),
            Effect::Rebind(_) => Some(GpuForm::Rebind),
            Effect::RestLengthRate(_) | Effect::PlasticReset(_) | Effect::Maturation(_) => None,
        }
    }
}

/// A registered kinetic rule; its [`Entry`] doc has the headings Rate,
/// References, Example.
pub trait KineticRule: Entry {
    fn effect(&self) -> Effect;
    /// Whether the rule's rates depend on kT (it then needs `temperature` > 0).
    fn needs_temperature(&self) -> bool {
        matches!(self.effect(), Effect::Unbind(_))
    }
    /// Whether the rule changes the rest length (the bond law must have `r0`).
    fn needs_rest_length(&self) -> bool {
        matches!(self.effect(), Effect::RestLengthRate(_) | Effect::PlasticReset(_))
    }
    /// Whether the rule changes a bound bond's law every step (rest length or
    /// stiffness scale), not only at events.
    fn evolves_every_step(&self) -> bool {
        matches!(self.effect(), Effect::RestLengthRate(_) | Effect::Maturation(_))
    }
}

/// A rule as used by a bond type, with its parameter values.
#[derive(Clone)]
pub struct RuleUse {
    pub rule: &'static dyn KineticRule,
    pub params: Vec<f64>,
}

impl std::fmt::Debug for RuleUse {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {:?}", self.rule.name(), self.params)
    }
}

/// Implements [`Entry`] and [`KineticRule`] for a unit struct (name = stem
/// of its `.md`, category `kinetic rule`).
macro_rules! kinetic_rule {
    ($ty:ident, $name:literal, $summary:literal, $effect:expr $(, validate = $validate:path)? $(, needs_temperature = $needs_kt:expr)?) => {
        $crate::interactions::entry!($ty, $name, "kinetic rule", $summary $(, validate = $validate)?);

        impl $crate::kinetics::KineticRule for $ty {
            fn effect(&self) -> $crate::kinetics::Effect {
                $effect
            }
            $(fn needs_temperature(&self) -> bool {
                $needs_kt
            })?
        }
    };
}
pub(crate) use kinetic_rule;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_have_unique_names_docs_and_files() {
        let mut seen = std::collections::HashSet::new();
        for r in RULES {
            assert!(seen.insert(r.name()), "duplicate {}", r.name());
            assert!(crate::interactions::lookup(r.name()).is_none(), "{} clashes with an interaction name", r.name());
            for heading in ["## Rate", "## References", "## Example"] {
                assert!(r.doc().contains(heading), "{} doc lacks {heading}", r.name());
            }
            for p in r.params() {
                assert!(!p.doc.is_empty());
                if let Some(d) = p.default {
                    p.check(d).unwrap();
                }
            }
            let path = format!("{}/src/kinetics/{}.rs", env!("CARGO_MANIFEST_DIR"), r.name());
            assert!(std::path::Path::new(&path).exists(), "{path}");
        }
    }
}
