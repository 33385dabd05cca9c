//! Per-particle virial and stress (LAMMPS `compute stress/atom`).
//!
//! # Definition
//!
//! The virial tensor of the thermo pressure, W = Σ_terms Σ_k r_k ⊗ f_k
//! (for a pair or bond, W = r_ij ⊗ f_ij with r_ij = x_i − x_j and f_ij the
//! force on i), is split among particles: each term's virial is divided
//! **equally among its particles**, as LAMMPS does for bonds, angles,
//! dihedrals and many-body terms. For a pair or bond (i, j):
//!
//! W_i = ½ r_ij ⊗ f_ij = −½ r_ji ⊗ f_ij,
//!
//! an angle gives ⅓ of its virial to each of its three particles, and a
//! surface (`body`) term 1/n to each of its n nodes. Hence Σ_i W_i = W, the
//! virial behind the thermo columns `pxx` … `pyz` (P = N·kT/V·I + W/V).
//! Units: energy (pN·µm in `cell` units), i.e. pressure × volume.
//!
//! # Sign convention
//!
//! W_i is positive under compression (repulsive pairs, compressed bonds)
//! and negative under tension. LAMMPS's `compute stress/atom` reports the
//! opposite sign, **S_i = −W_i** (stress × volume; positive in tension),
//! and dump columns `sxx` … `syz` follow LAMMPS; `wxx` … `wyz` are W_i.
//! Neither includes the ideal (Brownian) −kT·I per particle that the thermo
//! pressure adds. To turn S_i into a stress, divide by a volume per particle
//! (e.g. the Voronoi volume), as with LAMMPS.
//!
//! The von Mises stress of S (equal for W) is
//!
//! σ_vM = √(½[(S_xx − S_yy)² + (S_yy − S_zz)² + (S_zz − S_xx)²] + 3(S_xy² + S_xz² + S_yz²)),
//!
//! zero for a hydrostatic state S = −p·V·I; same units as S.
//!
//! # Example
//!
//! ```text
//! dump stress every 100 lammps stress.lammpstrj columns id type x y z sxx syy szz sxy sxz syz vonmises
//! ```

use crate::backend::CpuBackend;
use crate::system::{Model, SimBox, State};

/// Components in storage order: xx, yy, zz, xy, xz, yz.
pub type Sym6 = [f64; 6];

/// The per-particle virial W_i (xx, yy, zz, xy, xz, yz) at `state`; needs a
/// force evaluation of `backend` at `state` first.
pub fn per_particle_virial(backend: &CpuBackend, model: &Model, state: &State, sim_box: &SimBox) -> Vec<Sym6> {
    let mut out = vec![[0.0; 6]; model.len()];
    backend.for_each_term(model, state, sim_box, |term| {
        let mut w = [0.0; 6];
        for s in term.segments {
            let (d, f) = (s.d, s.force);
            let o = [d.x * f.x, d.y * f.y, d.z * f.z, d.x * f.y, d.x * f.z, d.y * f.z];
            (0..6).for_each(|k| w[k] += o[k]);
        }
        let share = 1.0 / term.particles.len() as f64;
        for &p in term.particles {
            (0..6).for_each(|k| out[p as usize][k] += share * w[k]);
        }
    });
    out
}

/// The von Mises equivalent of a symmetric tensor (xx, yy, zz, xy, xz, yz).
pub fn von_mises(s: &Sym6) -> f64 {
    let [xx, yy, zz, xy, xz, yz] = *s;
    (0.5 * ((xx - yy).powi(2) + (yy - zz).powi(2) + (zz - xx).powi(2)) + 3.0 * (xy * xy + xz * xz + yz * yz)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn von_mises_is_zero_for_hydrostatic_and_sqrt3_tau_for_shear() {
        assert_eq!(von_mises(&[-2.5, -2.5, -2.5, 0.0, 0.0, 0.0]), 0.0);
        // Uniaxial σ: von Mises = |σ|; pure shear τ: √3·τ.
        assert!((von_mises(&[4.0, 0.0, 0.0, 0.0, 0.0, 0.0]) - 4.0).abs() < 1e-15);
        assert!((von_mises(&[0.0, 0.0, 0.0, 0.0, 2.0, 0.0]) - 2.0 * 3f64.sqrt()).abs() < 1e-15);
        // Invariant under adding a hydrostatic part.
        let s = [1.0, -2.0, 0.5, 0.3, -0.7, 0.2];
        let shifted = [s[0] + 9.0, s[1] + 9.0, s[2] + 9.0, s[3], s[4], s[5]];
        assert!((von_mises(&s) - von_mises(&shifted)).abs() < 1e-12);
    }
}
