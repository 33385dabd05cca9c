//! Fracture of a cell sheet (Prakash, Bull & Prakash, Nat. Phys. 18, 444,
//! 2022): how its junctions failed — by rearrangement (flow, ductile) or by
//! opening cracks (brittle).
//!
//! # Definitions
//!
//! For a junction bond type T (thermo `fracture/T/QUANTITY`):
//!
//! - the **cells** are the particles that some bond of T joins in the
//!   topology; the **original junctions** are the topology's T bonds, the
//!   neighbour pairs of the sheet as built;
//! - a **broken** junction is an original pair that no bound T bond joins
//!   now (a junction that rebound to its old partner is not broken);
//! - a **rearrangement** is a bound T bond formed during the run (`bind`):
//!   a junction to a *new* neighbour, the second half of a T1 exchange (old
//!   bond breaks, new bond forms: the number of constraints is conserved);
//! - `ratio` = rearrangements / broken junctions: ≈ 1 when each lost
//!   junction was replaced by one to a new neighbour (the sheet flowed), ≈ 0
//!   when lost junctions were not replaced (it tore); 0 while none is broken;
//! - the **crack**: a triangle of the original junction network (three cells
//!   pairwise joined as built) is *open* when at least two of its three
//!   junctions are broken — a single broken junction between two triangles is
//!   a T1 in progress, not a crack, while a crack running between two rows of
//!   cells cuts two sides of every triangle it crosses. Open triangles that
//!   share a broken junction belong to one crack; `crack` is the number of
//!   broken junctions in the largest one (a straight crack across W cells
//!   of a hexagonal sheet cuts about 2W);
//! - `pieces`: connected components, of at least two cells, of the cells
//!   joined by bound T bonds now (a lone cell that came off is not a piece);
//!   the sheet has **separated** unless it is exactly one piece;
//! - `label`: 0 **elastic** (no junction broken), 1 **ductile** (some broken,
//!   one piece, and ratio ≥ ½: a majority of broken junctions were replaced
//!   by new neighbours — Prakash et al. call a material ductile when it passes from
//!   the intact state to the rearranged one a majority of the time), 2
//!   **brittle** (separated, or ratio < ½).
//!
//! Everything is read from the bond list and the bond state, so it is
//! restart-safe and identical for every thread count.

use std::collections::{HashMap, HashSet};

use crate::system::Model;

/// Which number `fracture/BONDTYPE/QUANTITY` reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FractureQuantity {
    Broken,
    Rearranged,
    Ratio,
    Crack,
    Pieces,
    Label,
}

impl FractureQuantity {
    pub const ALL: [FractureQuantity; 6] = [Self::Broken, Self::Rearranged, Self::Ratio, Self::Crack, Self::Pieces, Self::Label];

    pub fn name(self) -> &'static str {
        match self {
            Self::Broken => "broken",
            Self::Rearranged => "rearranged",
            Self::Ratio => "ratio",
            Self::Crack => "crack",
            Self::Pieces => "pieces",
            Self::Label => "label",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }

    /// Whether the quantity is a whole number.
    pub fn is_integer(self) -> bool {
        self != Self::Ratio
    }
}

/// The ductile/brittle label (thermo value in brackets).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FractureLabel {
    /// No junction broken (0).
    Elastic,
    /// Broken junctions mostly replaced by new neighbours, one piece (1).
    Ductile,
    /// Separated, or most broken junctions not replaced (2).
    Brittle,
}

/// The fracture state of a sheet's junctions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fracture {
    pub broken: usize,
    pub rearranged: usize,
    pub crack: usize,
    pub pieces: usize,
}

impl Fracture {
    /// Rearrangements per broken junction (0 while none is broken).
    pub fn ratio(&self) -> f64 {
        if self.broken == 0 {
            0.0
        } else {
            self.rearranged as f64 / self.broken as f64
        }
    }

    pub fn separated(&self) -> bool {
        self.pieces != 1
    }

    pub fn label(&self) -> FractureLabel {
        if self.broken == 0 && !self.separated() {
            FractureLabel::Elastic
        } else if self.separated() || self.ratio() < 0.5 {
            FractureLabel::Brittle
        } else {
            FractureLabel::Ductile
        }
    }

    pub fn value(&self, q: FractureQuantity) -> f64 {
        match q {
            FractureQuantity::Broken => self.broken as f64,
            FractureQuantity::Rearranged => self.rearranged as f64,
            FractureQuantity::Ratio => self.ratio(),
            FractureQuantity::Crack => self.crack as f64,
            FractureQuantity::Pieces => self.pieces as f64,
            FractureQuantity::Label => match self.label() {
                FractureLabel::Elastic => 0.0,
                FractureLabel::Ductile => 1.0,
                FractureLabel::Brittle => 2.0,
            },
        }
    }
}

fn pair(i: u32, j: u32) -> (u32, u32) {
    (i.min(j), i.max(j))
}

/// The fracture state of bond type `bond_type`; `bound` is the bond state's
/// flags (`None`: every bond bound).
pub fn fracture(model: &Model, bound: Option<&[bool]>, bond_type: usize) -> Fracture {
    let of_type = |b: usize| model.bond_type[b] as usize == bond_type;
    let is_bound = |b: usize| bound.is_none_or(|s| s[b]);
    let original: Vec<(u32, u32)> = {
        let mut pairs: Vec<(u32, u32)> =
            (0..model.topology_bonds).filter(|&b| of_type(b)).map(|b| pair(model.bonds[b][0], model.bonds[b][1])).collect();
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    };
    let joined: HashSet<(u32, u32)> =
        (0..model.bonds.len()).filter(|&b| of_type(b) && is_bound(b)).map(|b| pair(model.bonds[b][0], model.bonds[b][1])).collect();
    let broken: HashSet<(u32, u32)> = original.iter().copied().filter(|p| !joined.contains(p)).collect();
    let rearranged = (model.topology_bonds..model.bonds.len()).filter(|&b| of_type(b) && is_bound(b)).count();
    Fracture {
        broken: broken.len(),
        rearranged,
        crack: largest_crack(model.len(), &original, &broken),
        pieces: pieces(model.len(), &original, &joined),
    }
}

/// Union–find root with path halving.
fn root(parent: &mut [usize], mut k: usize) -> usize {
    while parent[k] != k {
        parent[k] = parent[parent[k]];
        k = parent[k];
    }
    k
}

/// Broken junctions in the largest cluster of open triangles.
fn largest_crack(n: usize, original: &[(u32, u32)], broken: &HashSet<(u32, u32)>) -> usize {
    let mut adjacency: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &(i, j) in original {
        adjacency[i as usize].push(j);
        adjacency[j as usize].push(i);
    }
    // Open triangles (a < b < c), each with its broken sides.
    let mut open: Vec<Vec<(u32, u32)>> = Vec::new();
    for &(a, b) in original {
        for &c in &adjacency[a as usize] {
            if c > b && adjacency[b as usize].contains(&c) {
                let cut: Vec<(u32, u32)> = [(a, b), pair(a, c), pair(b, c)].into_iter().filter(|p| broken.contains(p)).collect();
                if cut.len() >= 2 {
                    open.push(cut);
                }
            }
        }
    }
    // Join open triangles through the broken junctions they share.
    let mut parent: Vec<usize> = (0..open.len()).collect();
    let mut first_with: HashMap<(u32, u32), usize> = HashMap::new();
    for (t, cut) in open.iter().enumerate() {
        for p in cut {
            match first_with.get(p) {
                Some(&other) => {
                    let (ra, rb) = (root(&mut parent, t), root(&mut parent, other));
                    parent[ra] = rb;
                }
                None => {
                    first_with.insert(*p, t);
                }
            }
        }
    }
    let mut cracks: HashMap<usize, HashSet<(u32, u32)>> = HashMap::new();
    for (t, cut) in open.iter().enumerate() {
        let r = root(&mut parent, t);
        cracks.entry(r).or_default().extend(cut.iter().copied());
    }
    cracks.values().map(HashSet::len).max().unwrap_or(0)
}

/// Components of at least two cells among the cells of `original`, joined by `joined`.
fn pieces(n: usize, original: &[(u32, u32)], joined: &HashSet<(u32, u32)>) -> usize {
    let mut parent: Vec<usize> = (0..n).collect();
    for &(i, j) in joined {
        let (ri, rj) = (root(&mut parent, i as usize), root(&mut parent, j as usize));
        parent[ri] = rj;
    }
    let mut cells: Vec<usize> = original.iter().flat_map(|&(i, j)| [i as usize, j as usize]).collect();
    cells.sort_unstable();
    cells.dedup();
    let mut size = vec![0usize; n];
    for &c in &cells {
        let r = root(&mut parent, c);
        size[r] += 1;
    }
    size.iter().filter(|&&s| s >= 2).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Triangles of a strip: cells 0..n in two rows, bottom 0..w, top w..2w,
    /// joined along rows and zig-zag across.
    fn strip(w: u32) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        for k in 0..w - 1 {
            pairs.push((k, k + 1));
            pairs.push((w + k, w + k + 1));
        }
        for k in 0..w {
            pairs.push((k, w + k));
            if k + 1 < w {
                pairs.push((k + 1, w + k));
            }
        }
        pairs.into_iter().map(|(i, j)| pair(i, j)).collect()
    }

    #[test]
    fn a_cut_between_rows_is_one_crack_and_two_pieces() {
        let w = 5;
        let original = strip(w);
        let cross: HashSet<(u32, u32)> = original.iter().copied().filter(|&(i, j)| (i < w) != (j < w)).collect();
        assert_eq!(cross.len(), 2 * w as usize - 1);
        assert_eq!(largest_crack(2 * w as usize, &original, &cross), cross.len());
        let joined: HashSet<(u32, u32)> = original.iter().copied().filter(|p| !cross.contains(p)).collect();
        assert_eq!(pieces(2 * w as usize, &original, &joined), 2);
    }

    #[test]
    fn an_isolated_broken_junction_is_no_crack() {
        let original = strip(4);
        let one: HashSet<(u32, u32)> = [pair(1, 5)].into_iter().collect();
        assert_eq!(largest_crack(8, &original, &one), 0);
        let joined: HashSet<(u32, u32)> = original.iter().copied().filter(|p| !one.contains(p)).collect();
        assert_eq!(pieces(8, &original, &joined), 1);
    }

    #[test]
    fn labels_follow_ratio_and_separation() {
        let f = |broken, rearranged, pieces| Fracture { broken, rearranged, crack: 0, pieces }.label();
        assert_eq!(f(0, 0, 1), FractureLabel::Elastic);
        assert_eq!(f(10, 6, 1), FractureLabel::Ductile);
        assert_eq!(f(10, 4, 1), FractureLabel::Brittle);
        assert_eq!(f(10, 10, 2), FractureLabel::Brittle);
        assert_eq!(f(0, 0, 0), FractureLabel::Brittle);
    }
}
