//! Bond formation: new bonds between eligible particles that meet.
//!
//! A force-field line
//!
//! ```text
//! bind TYPE_A TYPE_B BONDTYPE k_on K capture R [max_bonds N]
//! ```
//!
//! lets every pair of a TYPE_A and a TYPE_B particle closer than R (minimum
//! image) form a bond of BONDTYPE at rate K (probability 1 − exp(−K·dt) per
//! step), unless either particle already has N bound bonds of that type
//! (default 1: one partner per site) or the two are already bound by one.
//! Candidate pairs are decided in parallel with Philox numbers keyed by
//! (seed, step, i, j) and accepted in ascending (i, j) order, so a particle
//! never exceeds its capacity and the outcome does not depend on threads.
//! Formed bonds are appended after the topology's and keep their index for
//! life: when a pair that already has an unbound bond of that type meets
//! again, that bond rebinds (a `rebind` event) instead of a new one forming,
//! so the bond list stays bounded. Formed bonds are recorded in the bond state
//! so that restarts resume them.

use rayon::prelude::*;

use crate::input::{parse_u64, InputError, Token};
use crate::integrate::rng::philox4x32_10;
use crate::interactions::ParamSpec;
use crate::neighbor::{Exclusions, NeighborList};
use crate::system::{Model, SimBox, State};
use crate::units::{Dim, UnitSystem};

/// Philox key salt separating formation decisions from every other stream.
const FORMATION_SALT: u32 = 0x6269_6E64; // ASCII "bind"

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
}

/// Parses `bind A B BONDTYPE k_on K capture R [max_bonds N]` (tokens after `bind`).
pub fn parse_bind(keyword: &Token, t: &[Token], units: UnitSystem) -> Result<BindLine, InputError> {
    if t.len() < 3 {
        return Err(keyword.error("expected `bind TYPE_A TYPE_B BONDTYPE k_on K capture R [max_bonds N]`"));
    }
    let max_at = t[3..].iter().position(|x| x.text == "max_bonds").map(|k| k + 3);
    let (values_end, max_bonds) = match max_at {
        Some(k) => {
            let v = t.get(k + 1).ok_or_else(|| t[k].error("`max_bonds` has no value; expected `max_bonds N`"))?;
            let n = parse_u64(v, "a maximum number of bonds per particle")?;
            if n == 0 || k + 2 != t.len() {
                return Err(v.error("expected `max_bonds N` with N >= 1 at the end of the line"));
            }
            (k, n as u32)
        }
        None => (t.len(), 1),
    };
    let values = crate::forcefield::parse_values(&PARAMS, "bind", keyword, &t[3..values_end], units)?;
    Ok(BindLine { type_a: t[0].clone(), type_b: t[1].clone(), bond_type: t[2].clone(), k_on: values[0], capture: values[1], max_bonds })
}

fn uniform_for_pair(seed: u64, step: u64, i: u32, j: u32) -> f64 {
    let x = philox4x32_10([i, j, step as u32, (step >> 32) as u32], [seed as u32, (seed >> 32) as u32 ^ FORMATION_SALT])[0];
    (x as f64 + 0.5) / 4_294_967_296.0
}

/// What a pair that binds this step does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Binding {
    /// A new bond of this type between these particles.
    New(u32, [u32; 2]),
    /// An existing unbound bond (index) between them binds again.
    Again(usize),
}

/// Finds the pairs that bind this step, in acceptance order.
pub struct Formation {
    neighbors: NeighborList,
    none: Exclusions,
}

impl Formation {
    pub fn new(model: &Model) -> Self {
        let capture = model.bind_rules.iter().map(|r| r.capture).fold(0.0, f64::max);
        Self { neighbors: NeighborList::new(capture, 0.0), none: Exclusions::none() }
    }

    /// The bindings decided at `step` from the positions of `state`.
    pub fn decide(
        &mut self,
        model: &Model,
        state: &State,
        sim_box: &SimBox,
        step: u64,
        dt: f64,
        seed: u64,
    ) -> Result<Vec<Binding>, String> {
        if model.bind_rules.is_empty() {
            return Ok(Vec::new());
        }
        self.neighbors.build(&state.positions, sim_box, &self.none)?;
        let bonds = state.bonds.as_ref().expect("bond state exists with bind rules");
        let x = &state.positions;
        // Candidate pairs i < j with their rule, decided independently in parallel.
        let candidates: Vec<(u32, u32, usize)> = (0..model.len())
            .into_par_iter()
            .flat_map_iter(|i| {
                let neighbors = &self.neighbors;
                neighbors.neighbors(i).iter().filter(move |&&j| (i as u32) < j).filter_map(move |&j| {
                    let (ti, tj) = (model.types[i], model.types[j as usize]);
                    let rule =
                        model.bind_rules.iter().position(|r| (r.type_a, r.type_b) == (ti, tj) || (r.type_a, r.type_b) == (tj, ti))?;
                    let r = &model.bind_rules[rule];
                    let d = sim_box.minimum_image(x[j as usize] - x[i]).length();
                    let p = -(-r.k_on * dt).exp_m1();
                    (d < r.capture && uniform_for_pair(seed, step, i as u32, j) < p).then_some((i as u32, j, rule))
                })
            })
            .collect();
        // Bound bonds per particle and rule, bound pairs, and unbound bonds to reuse.
        let rules = model.bind_rules.len();
        let mut count = vec![0u32; model.len() * rules];
        let mut bound_pairs = std::collections::HashSet::new();
        let mut unbound = std::collections::HashMap::new();
        for (b, &[i, j]) in model.bonds.iter().enumerate() {
            let key = (i.min(j), i.max(j), model.bond_type[b]);
            if !bonds.bound[b] {
                unbound.entry(key).or_insert(b);
                continue;
            }
            for (k, r) in model.bind_rules.iter().enumerate() {
                if model.bond_type[b] == r.bond_type {
                    count[i as usize * rules + k] += 1;
                    count[j as usize * rules + k] += 1;
                    bound_pairs.insert(key);
                }
            }
        }
        let mut bindings = Vec::new();
        for (i, j, k) in candidates {
            let r = &model.bind_rules[k];
            let (ci, cj) = (i as usize * rules + k, j as usize * rules + k);
            if count[ci] < r.max_bonds && count[cj] < r.max_bonds && bound_pairs.insert((i, j, r.bond_type)) {
                count[ci] += 1;
                count[cj] += 1;
                bindings.push(match unbound.get(&(i, j, r.bond_type)) {
                    Some(&b) => Binding::Again(b),
                    None => Binding::New(r.bond_type, [i, j]),
                });
            }
        }
        Ok(bindings)
    }
}
