//! Bond formation: new bonds between eligible particles that meet.
//!
//! A force-field line
//!
//! ```text
//! bind TYPE_A TYPE_B BONDTYPE k_on K capture R [max_bonds N] [partner random|nearest] [between any|bodies]
//! ```
//!
//! lets every pair of a TYPE_A and a TYPE_B particle closer than R (minimum
//! image) form a bond of BONDTYPE at rate K (probability 1 − exp(−K·dt) per
//! step), unless either particle already has N bound bonds of that type
//! (default 1: one partner per site) or the two are already bound by one.
//! With `partner nearest`, a pair is a candidate only if each is the other's
//! nearest eligible partner with free capacity (mutual-nearest, as LAMMPS
//! `fix bond/create` pairs closest candidates); ties go to the lower index.
//! With `between bodies`, only particles of two different bodies bind (cell–
//! cell junctions such as cadherin trans-dimers: the nodes of one cell's shell
//! never bind each other, however close).
//! Candidate pairs are decided in parallel with Philox numbers keyed by
//! (seed, step, i, j) and accepted in ascending (i, j) order, so a particle
//! never exceeds its capacity and the outcome does not depend on threads.
//! Formed bonds are appended after the topology's and keep their index for
//! life: when a pair that already has an unbound bond of that type meets
//! again, that bond rebinds (a `rebind` event) instead of a new one forming,
//! so the bond list stays bounded. Formed bonds are recorded in the bond state
//! so that restarts resume them.
//!
//! `partner nearest` with binding certain in a step (k_on·dt ≳ 37) is the rule
//! of LAMMPS `fix bond/create` (prob 1, `iparam`/`jparam` = max_bonds): each
//! particle picks its nearest eligible partner, the pair bonds if the choice
//! is mutual, so a particle gains at most one bond per rule and step.
//! `reference/bind.yaml` checks it (83 bonds form in four steps on a random
//! system, as many in each step in both engines). One difference remains:
//! LAMMPS never bonds a pair already joined by a bond of another type, cellmd
//! does.

use rayon::prelude::*;

use crate::neighbor::{Exclusions, NeighborList};
use crate::rng::philox4x32_10;
use crate::system::{Model, SimBox, State, StepClock};

/// Philox key salt separating formation decisions from every other stream.
pub const FORMATION_SALT: u32 = 0x6269_6E64; // ASCII "bind"

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
    /// The body of each particle (`forcefield::NO_BODY` outside bodies).
    body: Vec<u32>,
}

impl Formation {
    /// The candidate list has a skin of 0.3 × capture (capped so the box
    /// accepts it) and is rebuilt only when some particle moved more than
    /// half of it; it is sorted and candidates are filtered by their actual
    /// distance, so decisions do not depend on when it was rebuilt.
    pub fn new(model: &Model, sim_box: &SimBox) -> Self {
        let capture = model.bind_rules.iter().map(|r| r.capture).fold(0.0, f64::max);
        let lengths = sim_box.lengths();
        let room = (0..3).filter(|&a| sim_box.periodic[a]).map(|a| 0.5 * lengths[a] - capture).fold(f64::INFINITY, f64::min);
        let skin = (0.3 * capture).min(room.max(0.0));
        let body = model.body_of_particles();
        Self { neighbors: NeighborList::new(capture, skin), none: Exclusions::none(), body }
    }

    /// The bindings decided at the step `clock` describes, over its actual
    /// length, from the positions of `state`.
    pub fn decide(&mut self, model: &Model, state: &State, sim_box: &SimBox, clock: StepClock) -> Result<Vec<Binding>, String> {
        let StepClock { step, length: dt, seed, .. } = clock;
        if model.bind_rules.is_empty() {
            return Ok(Vec::new());
        }
        if self.neighbors.needs_rebuild(&state.positions, sim_box) {
            self.neighbors.build(&state.positions, sim_box, &self.none)?;
        }
        let bonds = state.bonds.as_ref().expect("bond state exists with bind rules");
        let x = &state.positions;
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
        // Eligible partners of particle i within capture: (j, rule, distance).
        let (neighbors, count_now, bound_now, body) = (&self.neighbors, &count, &bound_pairs, &self.body);
        let eligible = move |i: usize| {
            neighbors.neighbors(i).iter().filter_map(move |&j| {
                let (ti, tj) = (model.types[i], model.types[j as usize]);
                let k = model.bind_rules.iter().position(|r| r.joins_types(ti, tj))?;
                let r = &model.bind_rules[k];
                let key = ((i as u32).min(j), (i as u32).max(j), r.bond_type);
                let free = count_now[i * rules + k] < r.max_bonds && count_now[j as usize * rules + k] < r.max_bonds;
                let across = r.joins_bodies(body[i], body[j as usize]);
                let d = sim_box.minimum_image(x[j as usize] - x[i]).length();
                (d < r.capture && free && across && !bound_now.contains(&key)).then_some((j, k, d))
            })
        };
        // For `partner nearest`: each particle's nearest eligible partner per rule.
        let nearest: Vec<Vec<Option<u32>>> = (0..model.len())
            .into_par_iter()
            .map(|i| {
                let mut best: Vec<Option<(u32, f64)>> = vec![None; rules];
                for (j, k, d) in eligible(i) {
                    if best[k].is_none_or(|(bj, bd)| d < bd || (d == bd && j < bj)) {
                        best[k] = Some((j, d));
                    }
                }
                best.into_iter().map(|b| b.map(|(j, _)| j)).collect()
            })
            .collect();
        // Candidate pairs i < j, decided independently in parallel.
        let candidates: Vec<(u32, u32, usize)> = (0..model.len())
            .into_par_iter()
            .flat_map_iter(|i| {
                let nearest = &nearest;
                eligible(i).filter(move |&(j, _, _)| (i as u32) < j).filter_map(move |(j, k, _)| {
                    let r = &model.bind_rules[k];
                    let mutual = nearest[i][k] == Some(j) && nearest[j as usize][k] == Some(i as u32);
                    let p = -(-r.k_on * dt).exp_m1();
                    ((!r.nearest || mutual) && uniform_for_pair(seed, step, i as u32, j) < p).then_some((i as u32, j, k))
                })
            })
            .collect();
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
