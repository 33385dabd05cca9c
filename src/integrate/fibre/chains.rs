//! Which particles form fibres: linear chains of bonds, found once when the
//! system (or its constraint list) changes, so that each fibre's terms can
//! be solved as one banded block ([`super::kkt`]).
//!
//! A **constrained chain** is a connected component of the constrained
//! bonds (`constrain`) that is a simple path: every particle on at most two
//! of them, no cycle, no two bonds on one pair. In a component that is not
//! a path (fibres joined by constrained crosslinks, a branch point), the
//! simple paths of one bond type are chains too, the longest first, each
//! through particles no chain holds yet; its other constraints are the
//! couplings restored with the chains after the step ([`super::coupled`]).
//! What touches no chain (a ring, a branched graph of one type) stays with
//! the general projection (SHAKE after the explicit step, projected
//! conjugate gradients in the implicit one). An **elastic chain**
//! is a path of at least two bonds of one unconstrained bond type through
//! particles no other chain holds: the implicit step solves its bonds and
//! bending in the same banded block (stiff harmonic segments of a filament).
//!
//! Each chain is ordered from the end with the lower particle index, so the
//! layout — and with it every sum — is the same on any thread count. Its
//! **joints** are the angle terms on three consecutive points whose law is
//! a fibre bending E = s·(1 − t₁·t₂) (`wlc_bending`, `cosine_angle`): their
//! stiffness enters the chain's block — an inextensible chain's solver
//! owns them; an elastic chain's keeps them generic terms (exact Hessian)
//! and uses their isotropic matrix in its preconditioner only — while other
//! angle laws on a chain stay generic terms.

use crate::system::Model;

/// One fibre: its points in order along the chain and what lies between them.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// Particle indices p₀ … p_n along the chain.
    pub points: Vec<u32>,
    /// Bond index of each segment k (between points k and k + 1).
    pub bonds: Vec<u32>,
    /// Index into the constraint list of each segment (constrained chains), or empty.
    pub constraints: Vec<u32>,
    /// Angle terms of fibre-bending laws, by joint: (interior point m, angle index).
    pub joints: Vec<(u32, u32)>,
}

impl Chain {
    pub fn is_constrained(&self) -> bool {
        !self.constraints.is_empty()
    }

    pub fn segments(&self) -> usize {
        self.bonds.len()
    }
}

/// The chains of a model, with the terms they own.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Chains {
    pub chains: Vec<Chain>,
    /// For each particle: its chain and point index, or `None`.
    pub place: Vec<Option<(u32, u32)>>,
    /// Bonds whose stiffness a chain's block carries, or whose length its
    /// constraint rows or the coupled projection hold (the generic stiffness
    /// skips them: along an inextensible bond its law is replaced by the
    /// constraint).
    pub owned_bonds: Vec<bool>,
    /// Angles whose stiffness a chain's block carries.
    pub owned_angles: Vec<bool>,
    /// Constraint-list entries solved by a chain (the general projection skips them).
    pub chained_constraints: Vec<bool>,
}

/// The simple paths among `edges` (bond indices), each ordered from its end
/// with the lower particle index; components that are not paths are left out.
fn paths(model: &Model, edges: &[u32], taken: &[bool]) -> Vec<(Vec<u32>, Vec<u32>)> {
    let n = model.len();
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &b in edges {
        let [i, j] = model.bonds[b as usize];
        incident[i as usize].push(b);
        incident[j as usize].push(b);
    }
    let mut visited = vec![false; n];
    let mut found = Vec::new();
    for start in 0..n {
        if visited[start] || incident[start].is_empty() {
            continue;
        }
        // The component of `start`, and whether it is a path.
        let mut component = vec![start as u32];
        visited[start] = true;
        let mut k = 0;
        let mut bonds = 0;
        let mut is_path = true;
        while k < component.len() {
            let p = component[k] as usize;
            k += 1;
            is_path &= incident[p].len() <= 2 && !taken[p];
            for &b in &incident[p] {
                bonds += 1;
                let [i, j] = model.bonds[b as usize];
                let other = if i as usize == p { j } else { i } as usize;
                if other == p {
                    is_path = false;
                } else if !visited[other] {
                    visited[other] = true;
                    component.push(other as u32);
                }
            }
        }
        // Each bond was counted from both ends; a path has one bond fewer than points.
        if !is_path || bonds / 2 + 1 != component.len() {
            continue;
        }
        let end = component.iter().copied().filter(|&p| incident[p as usize].len() == 1).min().expect("a path has two ends");
        let (mut points, mut along) = (vec![end], Vec::new());
        let mut previous = u32::MAX;
        let mut at = end;
        while let Some(&b) = incident[at as usize].iter().find(|&&b| b != previous) {
            let [i, j] = model.bonds[b as usize];
            at = if i == at { j } else { i };
            points.push(at);
            along.push(b);
            previous = b;
        }
        found.push((points, along));
    }
    found
}

impl Chains {
    /// The chains of `model` with the constraint list `constrained` (bond
    /// indices, in list order): with `chain_constraints`, the constrained
    /// chains; with `elastic`, the elastic chains, which never take a
    /// constrained bond.
    pub fn find(
        model: &Model,
        constrained: &[usize],
        chain_constraints: bool,
        elastic: bool,
        strength: impl Fn(u32) -> Option<f64>,
    ) -> Chains {
        let n = model.len();
        let mut place = vec![None; n];
        let mut owned_bonds = vec![false; model.bonds.len()];
        let mut chained_constraints = vec![false; constrained.len()];
        let mut taken = vec![false; n];
        let mut chains = Vec::new();
        let mut list_index = vec![u32::MAX; model.bonds.len()];
        for (k, &b) in constrained.iter().enumerate() {
            list_index[b] = k as u32;
        }
        let edges: Vec<u32> = constrained.iter().filter(|_| chain_constraints).map(|&b| b as u32).collect();
        let mut groups: Vec<(Vec<u32>, Vec<u32>, bool)> = paths(model, &edges, &taken).into_iter().map(|(p, b)| (p, b, true)).collect();
        for (points, _, _) in &groups {
            points.iter().for_each(|&p| taken[p as usize] = true);
        }
        // A constraint graph that is no path (fibres joined by constrained
        // crosslinks, a branched fibre) still holds fibres: the paths of one
        // bond type each, the longest first, the rest its couplings.
        let mut in_chain = vec![false; model.bonds.len()];
        groups.iter().flat_map(|(_, bonds, _)| bonds).for_each(|&b| in_chain[b as usize] = true);
        let mut typed: Vec<(Vec<u32>, Vec<u32>)> = (0..model.bond_types.len() as u32)
            .flat_map(|t| {
                let edges: Vec<u32> =
                    edges.iter().copied().filter(|&b| model.bond_type[b as usize] == t && !in_chain[b as usize]).collect();
                paths(model, &edges, &taken)
            })
            .collect();
        typed.sort_by_key(|(_, bonds)| std::cmp::Reverse(bonds.len()));
        for (points, bonds) in typed {
            if points.iter().all(|&p| !taken[p as usize]) {
                points.iter().for_each(|&p| taken[p as usize] = true);
                groups.push((points, bonds, true));
            }
        }
        if elastic {
            let is_constrained: Vec<bool> = (0..model.bonds.len()).map(|b| list_index[b] != u32::MAX).collect();
            for t in 0..model.bond_types.len() as u32 {
                let edges: Vec<u32> =
                    (0..model.bonds.len() as u32).filter(|&b| model.bond_type[b as usize] == t && !is_constrained[b as usize]).collect();
                for (points, bonds) in paths(model, &edges, &taken) {
                    if bonds.len() >= 2 {
                        points.iter().for_each(|&p| taken[p as usize] = true);
                        groups.push((points, bonds, false));
                    }
                }
            }
        }
        for (c, (points, bonds, constrained)) in groups.into_iter().enumerate() {
            for (m, &p) in points.iter().enumerate() {
                place[p as usize] = Some((c as u32, m as u32));
            }
            bonds.iter().for_each(|&b| owned_bonds[b as usize] = true);
            let constraints = if constrained { bonds.iter().map(|&b| list_index[b as usize]).collect() } else { Vec::new() };
            for &k in &constraints {
                chained_constraints[k as usize] = true;
            }
            chains.push(Chain { points, bonds, constraints, joints: Vec::new() });
        }
        // A constrained bond on a chain's point outside the chains (a
        // constrained crosslink) is held by the projection after the step
        // (`super::coupled`), which the implicit step leaves it to: its law's
        // stiffness along it would otherwise resist that step.
        for &b in &edges {
            let [i, j] = model.bonds[b as usize];
            if !owned_bonds[b as usize] && (place[i as usize].is_some() || place[j as usize].is_some()) {
                owned_bonds[b as usize] = true;
            }
        }
        let mut owned_angles = vec![false; model.angles.len()];
        for (a, &[i, j, k]) in model.angles.iter().enumerate() {
            let (Some((c, m)), Some((ci, mi)), Some((ck, mk))) = (place[j as usize], place[i as usize], place[k as usize]) else {
                continue;
            };
            let consecutive = ci == c && ck == c && mi.abs_diff(m) == 1 && mk.abs_diff(m) == 1 && mi != mk;
            if consecutive && strength(model.angle_type[a]).is_some() {
                chains[c as usize].joints.push((m, a as u32));
                owned_angles[a] = chains[c as usize].is_constrained();
            }
        }
        Chains { chains, place, owned_bonds, owned_angles, chained_constraints }
    }

    pub fn is_empty(&self) -> bool {
        self.chains.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::fibre::test_model;

    /// Particles 1…n on the x axis; bonds and angles given as topology lines (ids 1-based).
    fn model(n: usize, bonds: &str, angles: &str) -> Model {
        let particles: String = (1..=n).map(|i| format!("{i} p {} 0 0\n", i as f64 * 0.1)).collect();
        let top = format!("[ particles ]\n{particles}[ bonds ]\n{bonds}[ angles ]\n{angles}");
        test_model(&top, "particle p drag 1\nbond s harmonic k 1 r0 0.1\nbond x harmonic k 1 r0 0.1\nangle a wlc_bending kappa 1 l0 0.1\n")
    }

    #[test]
    fn paths_are_chains_and_branches_are_not() {
        // 1-2-3-4 (listed out of order), a star 5-6, 5-7, 5-8 and a ring 9-10-11.
        let bonds = "s 2 1\ns 2 3\ns 4 3\ns 5 6\ns 5 7\ns 5 8\ns 9 10\ns 10 11\ns 11 9\n";
        let m = model(11, bonds, "a 1 2 3\na 2 3 4\na 6 5 7\n");
        let all: Vec<usize> = (0..9).collect();
        let chains = Chains::find(&m, &all, true, false, |_| Some(1.0));
        assert_eq!(chains.chains.len(), 1);
        let chain = &chains.chains[0];
        assert_eq!(chain.points, vec![0, 1, 2, 3]);
        assert_eq!(chain.bonds, vec![0, 1, 2]);
        assert_eq!(chain.constraints, vec![0, 1, 2]);
        assert_eq!(chain.joints, vec![(1, 0), (2, 1)]);
        assert_eq!(chains.owned_angles, vec![true, true, false]);
        // The chain's segment bonds are held by its constraints, not by the generic stiffness.
        assert_eq!(chains.owned_bonds, [vec![true; 3], vec![false; 6]].concat());
        assert_eq!(chains.chained_constraints.iter().filter(|&&c| c).count(), 3);
        assert_eq!(chains.place[2], Some((0, 2)));
        assert_eq!(chains.place[4], None);
        // A law that is no fibre bending owns no joint.
        assert!(Chains::find(&m, &all, true, false, |_| None).chains[0].joints.is_empty());
    }

    #[test]
    fn elastic_chains_take_the_particles_no_constrained_chain_holds() {
        // Constrained 1-2-3; elastic 4-5-6 of type s; 3-4 of type x is a single bond and no chain.
        let m = model(6, "s 1 2\ns 2 3\ns 4 5\ns 5 6\nx 3 4\n", "");
        let chains = Chains::find(&m, &[0, 1], true, true, |_| None);
        let points: Vec<_> = chains.chains.iter().map(|c| c.points.clone()).collect();
        assert_eq!(points, vec![vec![0, 1, 2], vec![3, 4, 5]]);
        assert!(chains.chains[0].is_constrained() && !chains.chains[1].is_constrained());
        assert_eq!(chains.owned_bonds, vec![true, true, true, true, false]);
        // Without elastic chains only the constrained one.
        assert_eq!(Chains::find(&m, &[0, 1], true, false, |_| None).chains.len(), 1);
        // Constrained bonds solved elsewhere (SHAKE) are in no chain, elastic or not.
        let shaken = Chains::find(&m, &[0, 1], false, true, |_| None);
        assert_eq!(shaken.chains.iter().map(|c| c.points.clone()).collect::<Vec<_>>(), vec![vec![3, 4, 5]]);
    }
}
