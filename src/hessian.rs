//! Local Hessians of interaction terms, for the stiffness matrix of the
//! linearly implicit step (`backend::stiffness`, a layer above, assembles it).
//!
//! A term acting on k particles (an angle, an external field, one face or one
//! node's one-ring of a body) has a 3k×3k Hessian H = ∂²E/∂x∂x. The implicit
//! step needs the sum of such blocks to be positive semi-definite, so that
//! γ/dt·I + K̃ is symmetric positive definite for every dt:
//!
//! - [`finite_difference_hessian`]: H from the term's analytic forces by
//!   central differences, column b = −(F(x + h·e_b) − F(x − h·e_b))/(2h) with
//!   h = 10⁻⁶ × the term's size, symmetrised (the fallback where H is not
//!   written analytically).
//! - [`project_psd`]: the positive semi-definite part Σ_e max(λ_e, 0)·v_e v_eᵀ
//!   of a symmetric H (faer's self-adjoint eigensolver). Projecting term by
//!   term keeps K̃ ⪰ Σ_t H_t: it only adds stiffness where a term alone is
//!   concave, and leaves every convex term exact.
//! - [`SurfaceHessian`]: what a surface (body) term hands the backend — local
//!   stencil Hessians (projected there), local Gauss–Newton terms w·g gᵀ
//!   (PSD as they stand) and Gauss–Newton terms over the whole body (a volume
//!   or total-area term couples every node, so it stays a vector instead of
//!   a dense block).
//!
//! Area terms share one stencil, [`SurfaceHessian::push_face`]: a face energy
//! e(A_t) with tension τ = e′(A_t) and curvature c = e″(A_t) has the 9×9 Hessian
//! c·∇A_t ∇A_tᵀ + τ·∇²A_t ([`crate::mesh::triangle_area_hessian`]).

use faer::{Mat, Side};
use glam::{DMat3, DVec3};

use crate::mesh::{triangle_area_gradient, triangle_area_hessian};

/// The Hessian −∂F/∂x of a term with forces `forces` at `at` by central
/// differences, symmetrised (3k×3k for k particles).
pub fn finite_difference_hessian(at: &[DVec3], forces: impl Fn(&[DVec3]) -> Vec<DVec3>) -> Mat<f64> {
    let size = at.iter().map(|x| (*x - at[0]).length()).fold(0.0, f64::max).max(at[0].length()).max(1e-3);
    let h = 1e-6 * size;
    let dim = 3 * at.len();
    let mut hessian = Mat::<f64>::zeros(dim, dim);
    let mut moved = at.to_vec();
    for b in 0..at.len() {
        for axis in 0..3 {
            moved[b][axis] = at[b][axis] + h;
            let fp = forces(&moved);
            moved[b][axis] = at[b][axis] - h;
            let fm = forces(&moved);
            moved[b][axis] = at[b][axis];
            for a in 0..at.len() {
                for row in 0..3 {
                    hessian[(3 * a + row, 3 * b + axis)] = -(fp[a][row] - fm[a][row]) / (2.0 * h);
                }
            }
        }
    }
    Mat::from_fn(dim, dim, |r, c| 0.5 * (hessian[(r, c)] + hessian[(c, r)]))
}

/// The positive semi-definite part of the symmetric matrix `h` (negative
/// eigenvalues set to 0); zero if the eigensolver fails.
pub fn project_psd(h: &Mat<f64>) -> Mat<f64> {
    let dim = h.nrows();
    let Ok(eigen) = h.self_adjoint_eigen(Side::Lower) else { return Mat::zeros(dim, dim) };
    let (u, s) = (eigen.U(), eigen.S().column_vector());
    if (0..dim).all(|e| s[e] >= 0.0) {
        return h.clone();
    }
    // V·Vᵀ with V the eigenvectors scaled by √max(λ, 0).
    let scaled = Mat::from_fn(dim, dim, |r, e| u[(r, e)] * s[e].max(0.0).sqrt());
    &scaled * scaled.transpose()
}

/// The 3×3 block (a, b) of a 3k×3k matrix.
pub fn block(h: &Mat<f64>, a: usize, b: usize) -> DMat3 {
    let column = |col: usize| DVec3::from_array([0, 1, 2].map(|row| h[(3 * a + row, 3 * b + col)]));
    DMat3::from_cols(column(0), column(1), column(2))
}

/// A stencil's Hessian over `nodes` (local node numbers of the body), not yet projected.
#[derive(Clone, Debug)]
pub struct LocalHessian {
    pub nodes: Vec<u32>,
    pub matrix: Mat<f64>,
}

/// A Gauss–Newton term w·g gᵀ (w ≥ 0) on a stencil `nodes`: positive
/// semi-definite as it stands, assembled as blocks without projection.
#[derive(Clone, Debug)]
pub struct LocalRankOne {
    pub weight: f64,
    pub nodes: Vec<u32>,
    pub gradient: Vec<DVec3>,
}

/// A Gauss–Newton term w·g gᵀ (w ≥ 0), g over every node of the body.
#[derive(Clone, Debug)]
pub struct RankOne {
    pub weight: f64,
    pub gradient: Vec<DVec3>,
}

/// The second-order model of one surface term on one body: the sum of the
/// stencils' projections and the Gauss–Newton terms is its block of K̃.
#[derive(Clone, Debug, Default)]
pub struct SurfaceHessian {
    /// Local Hessians, projected onto their PSD part by the backend.
    pub stencils: Vec<LocalHessian>,
    /// Local Gauss–Newton terms (PSD already).
    pub gauss_newton: Vec<LocalRankOne>,
    /// Gauss–Newton terms over the whole body (applied matrix-free).
    pub rank_one: Vec<RankOne>,
}

impl SurfaceHessian {
    /// Adds the Hessian c·∇A_t ∇A_tᵀ + τ·∇²A_t of a face energy e(A_t) with
    /// e′ = `tension` and e″ = `curvature`, at corners `corners` of face `face`.
    pub fn push_face(&mut self, face: [u32; 3], corners: [DVec3; 3], tension: f64, curvature: f64) {
        let (_, g) = triangle_area_gradient(corners);
        let second = triangle_area_hessian(corners);
        let matrix = Mat::from_fn(9, 9, |r, c| {
            let (a, b, i, j) = (r / 3, c / 3, r % 3, c % 3);
            curvature * g[a][i] * g[b][j] + tension * second[a][b].col(j)[i]
        });
        self.stencils.push(LocalHessian { nodes: face.to_vec(), matrix });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Projection keeps a PSD Hessian and removes negative curvature.
    #[test]
    fn projection_of_a_compressed_spring_keeps_only_its_axial_stiffness() {
        // A compressed spring between two particles: exact Hessian indefinite.
        let (k, r0) = (2.0, 2.0);
        let forces = |p: &[DVec3]| {
            let d = p[1] - p[0];
            let f = k * (d.length() - r0) * d / d.length();
            vec![f, -f]
        };
        let projected = project_psd(&finite_difference_hessian(&[DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0)], forces));
        let quadratic = |v: [DVec3; 2]| -> f64 {
            (0..2).flat_map(|a| (0..2).map(move |b| (a, b))).map(|(a, b)| v[a].dot(block(&projected, a, b) * v[b])).sum()
        };
        // v = transverse relative motion: exact vᵀHv = 2·k(r − r0)/r < 0; projected ≥ 0.
        let transverse = quadratic([DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.0, -1.0, 0.0)]);
        assert!(transverse.abs() < 1e-6, "transverse curvature {transverse} should be projected to 0");
        let axial = quadratic([DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0)]);
        assert!((axial - 4.0 * k).abs() < 1e-5, "axial curvature {axial}, expected 4k");
        // A stretched spring's Hessian is PSD already (up to rounding in its null space): kept.
        let stretched = finite_difference_hessian(&[DVec3::ZERO, DVec3::new(3.0, 0.5, 0.0)], forces);
        let change = (project_psd(&stretched) - &stretched).norm_max();
        assert!(change < 1e-9 * stretched.norm_max(), "projection changed a PSD Hessian by {change:e}");
    }
}
