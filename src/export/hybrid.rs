//! The `hybrid` styles of an exported deck: each LAMMPS sub-style in order
//! of first use with the cellmd interactions it stands for (bonds, angles),
//! and the `pair_style hybrid/overlay` instances of the pair rules.

use std::collections::BTreeMap;

use super::styles::{self, PairStyled, Styled};
use crate::forcefield::TermType;
use crate::system::Model;

/// Sub-styles in order of first use, and the sub-style of each type.
pub(super) struct Hybrid {
    pub(super) styles: Vec<&'static str>,
    /// The cellmd interactions each sub-style stands for (energy keys).
    pub(super) interactions: Vec<Vec<&'static str>>,
    pub(super) per_type: Vec<Styled>,
}

impl Hybrid {
    pub(super) fn new(types: &[TermType], map: fn(&TermType) -> Result<Styled, String>) -> Result<Self, String> {
        let mut h = Hybrid { styles: Vec::new(), interactions: Vec::new(), per_type: Vec::new() };
        for t in types {
            let s = map(t)?;
            let k = h.styles.iter().position(|&x| x == s.style).unwrap_or_else(|| {
                h.styles.push(s.style);
                h.interactions.push(Vec::new());
                h.styles.len() - 1
            });
            if !h.interactions[k].contains(&t.interaction.name()) {
                h.interactions[k].push(t.interaction.name());
            }
            h.per_type.push(s);
        }
        Ok(h)
    }
}

/// One `pair_style hybrid/overlay` instance: a style serving one cellmd interaction.
pub(super) struct PairInstance {
    pub(super) interaction: &'static str,
    pub(super) style: &'static str,
    pub(super) shift: bool,
    /// `lj/cut 2` when the style appears more than once, else `lj/cut`.
    pub(super) reference: String,
}

pub(super) struct Pairs {
    pub(super) instances: Vec<PairInstance>,
    /// For each pair rule: its instance and converted coefficients.
    pub(super) per_rule: Vec<(usize, PairStyled)>,
    pub(super) max_cutoff: f64,
}

impl Pairs {
    pub(super) fn new(model: &Model) -> Result<Self, String> {
        let mut instances: Vec<PairInstance> = Vec::new();
        let mut per_rule = Vec::new();
        // The n-th rule of an interaction on one type pair uses that interaction's n-th instance.
        let mut seen: BTreeMap<(u32, u32, &'static str), usize> = BTreeMap::new();
        for (rule, term) in model.pair_rules.iter().enumerate() {
            let styled = styles::pair(term)?;
            let (a, b) = model.pair_rule_types[rule];
            let nth = seen.entry((a.min(b), a.max(b), term.interaction.name())).or_default();
            let mut found = None;
            let mut count = 0;
            for (k, inst) in instances.iter().enumerate() {
                if inst.interaction == term.interaction.name() {
                    if count == *nth {
                        found = Some(k);
                    }
                    count += 1;
                }
            }
            let k = found.unwrap_or_else(|| {
                instances.push(PairInstance {
                    interaction: term.interaction.name(),
                    style: styled.style,
                    shift: styled.shift,
                    reference: String::new(),
                });
                instances.len() - 1
            });
            *nth += 1;
            per_rule.push((k, styled));
        }
        let names: Vec<&str> = instances.iter().map(|i| i.style).collect();
        let mut index: BTreeMap<&str, usize> = BTreeMap::new();
        for inst in &mut instances {
            let n = index.entry(inst.style).or_default();
            *n += 1;
            inst.reference =
                if names.iter().filter(|&&s| s == inst.style).count() > 1 { format!("{} {n}", inst.style) } else { inst.style.to_string() };
        }
        let max_cutoff = per_rule.iter().map(|(_, s)| s.cutoff).fold(0.0, f64::max);
        Ok(Pairs { instances, per_rule, max_cutoff })
    }

    pub(super) fn coeff_line(&self, model: &Model, rule: usize, term: &TermType) -> Result<String, String> {
        let (a, b) = model.pair_rule_types[rule];
        let (k, _) = &self.per_rule[rule];
        let styled = styles::pair(term)?;
        Ok(format!("pair_coeff {} {} {} {}", a.min(b) + 1, a.max(b) + 1, self.instances[*k].reference, styled.coeffs))
    }
}
