//! Area-weighted contact terms between bodies on the GPU (`contact` lines
//! with an area law: `contact_adhesion`). Kernels in
//! shaders/common/adhesion.wgsl; the CPU oracle is src/backend/adhesion.rs,
//! whose equations these follow: a rule with density ε and switch s(d)
//! gives E = ε·Σ_t A_t·s_a·s_b·s_c over the faces t of the bodies it names,
//! s_k = s(d_k) with d_k the distance of node k to its nearest face of a body
//! the rule pairs it with; with P_t = s_a·s_b·s_c and
//! B_k = Σ_{t ∋ k} A_t·Π_{c ∈ t, c ≠ k} s_c, the forces are
//! −ε·P_t·∂A_t/∂x on the faces' corners (the area part) and, at each node's
//! nearest face, a node–face pull of b′ = ε·s′_k·B_k (the distance part).
//!
//! # Candidates and reach
//!
//! The node–face pairs are those of the contact search (src/gpu/contact.rs):
//! the neighbour list reaches d̂ + ℓ beyond the pair cutoff, d̂ the largest
//! range of any contact rule, the adhesion's d_off included, and a face edge
//! that outgrows ℓ halts the run as for the barrier. Every face within d̂ of
//! a node is seen from its row, so each node's nearest face within a rule's
//! range is the CPU's (beyond it s = 0 on both). Ties go to the lower face
//! index, as on the CPU (its pairs are sorted by face).
//!
//! # Passes (no float atomics; each value written by one invocation)
//!
//! 1. `adhesion_nodes` (per contact node, per neighbour-list chunk): the
//!    node part of the contact pass (`contact_node_part`: node–face terms
//!    on the node, its closest distance) added to `force[i]`, the closest
//!    distance kept in `surf` for the step clamp, and per rule the nearest
//!    face, then s and s′ there.
//! 2. `adhesion_weights` (per particle): B_k per rule from the node's faces
//!    (in face order) and the pull ε·s′_k·B_k.
//! 3. `contact_forces` (the contact pass, src/gpu/contact.rs) adds, per
//!    particle, the area part over its faces (face order; the energy
//!    ε·A_t·P_t on the face's first corner), its own pull −b′·n̂ at its
//!    nearest face, and, as a face corner, b′·w_k·n̂ for every node whose
//!    nearest face it is (in the order of its contact row), then takes the
//!    step fraction from the final force.
//!
//! A pair's geometry is computed from the face's first corner (as for the
//! barrier), so the node and the corners see the same bits of d, w and n̂;
//! each particle sums its contributions in an order fixed by the data: the
//! same run twice gives the same bits.
//!
//! # Memory and cost
//!
//! `surf` holds (1 + 2R)·N vec4 entries for R area rules (their own region
//! after the fraction ring). Per step: the node pass scans the node's row
//! once (the barrier's node loop, moved there), the weight pass visits each
//! node's ≈ 6 faces per rule, and the contact pass adds a face loop and,
//! per (corner, node) pair it already evaluates, one comparison per rule.

use crate::interactions::ContactLaw;
use crate::system::Model;

/// The area-weighted rules and their tables in `topo`.
#[derive(Default)]
pub struct AdhesionPack {
    /// The rule slots per (node body type, face body type) (CSR: offsets,
    /// then slots), and each slot's index into `Model::contact_rules`.
    sections: [Vec<u32>; 3],
}

/// The largest face index the kernels can keep (as an exact f32 in `surf`).
const MAX_FACES: u32 = 1 << 24;

impl AdhesionPack {
    /// The area-weighted rules of `model`, whose contact bodies have `faces`
    /// faces; an error where the kernels cannot index them.
    pub fn new(model: &Model, faces: u32) -> Result<Self, String> {
        let area = |r: usize| matches!(model.contact_rules[r].law, ContactLaw::Area { .. });
        let rules: Vec<u32> = (0..model.contact_rules.len()).filter(|&r| area(r)).map(|r| r as u32).collect();
        if rules.is_empty() {
            return Ok(Self::default());
        }
        if faces >= MAX_FACES {
            return Err(format!(
                "area-weighted contact terms (`contact_adhesion`) on the GPU index at most {MAX_FACES} faces of contact bodies, \
                 found {faces}; use `device cpu`"
            ));
        }
        let types = model.body_type_names.len();
        let slots: Vec<Vec<u32>> = (0..types * types)
            .map(|ab| {
                let covered: Vec<usize> = model.contact_rules_between((ab / types) as u32, (ab % types) as u32).collect();
                (0..rules.len() as u32).filter(|&j| covered.contains(&(rules[j as usize] as usize))).collect()
            })
            .collect();
        let mut sections: [Vec<u32>; 3] = Default::default();
        let (offsets, flat) = sections.split_at_mut(1);
        super::pack::push_csr(&slots, &mut offsets[0], &mut flat[0]);
        sections[2] = rules;
        Ok(Self { sections })
    }

    /// The number of area-weighted rules (0: no adhesion passes).
    pub fn rules(&self) -> u32 {
        self.sections[2].len() as u32
    }

    /// Entries of `surf` the adhesion passes use for `n` particles: per
    /// particle and rule its (s, s′, nearest face, s″) and its (pull,
    /// Gauss–Newton weight).
    pub fn surf_entries(&self, n: u32) -> u64 {
        n as u64 * 2 * self.rules() as u64
    }

    /// Appends the sections to `topo` and returns layout.wgsl's adhesion
    /// fields, with the `surf` regions from entry `surf_base` on and the
    /// contact pass's closest distances at `closest` (the contact pack's
    /// `closest_entry`, in the pass this one runs around).
    pub fn append(&self, topo: &mut Vec<u32>, surf_base: u64, n: u32, closest: u32) -> [u32; 8] {
        let mut fields = [0u32; 8];
        for (k, section) in self.sections.iter().enumerate() {
            fields[k] = topo.len() as u32;
            topo.extend(section);
        }
        let (base, rules) = (surf_base as u32, self.rules());
        fields[3..7].copy_from_slice(&[rules, closest, base, base + n * rules]);
        fields
    }
}
