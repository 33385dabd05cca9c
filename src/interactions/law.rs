//! The laws of the interaction types: [`Law`], the evaluator of a type by
//! family (what the registry declares), and the per-kind laws ([`KindLaw`]:
//! [`RadialLaw`], [`AngleLaw`], …) that a term of one kind is evaluated
//! through once its law is taken out of the [`Law`] (`forcefield::Typed`).

use glam::DVec3;

use super::{FourBody, OneBody, Radial, SurfaceHessian, SurfaceMesh, TetraRest, ThreeBody, Volumetric};

/// The evaluator of an interaction type, by family.
#[derive(Clone, Copy)]
pub enum Law {
    /// E(r) for bonds and pairs. `range` is the cutoff beyond which E ≡ 0
    /// (used for pair neighbour lists; `f64::INFINITY` for bonds).
    ///
    /// `force(p, r²)` is (dE/dr)/r, the force on particle i being
    /// (x_j − x_i)·force: what the step loop calls. It is the same
    /// derivative as `eval`'s without the energy and d²E/dr², so it skips
    /// their work (`soft` takes a sine, no cosine), and it takes r² so a law
    /// that needs no r skips the square root (`wca`, `lj`). `radial_force!`
    /// derives it from `eval`: inlined, the unused energy terms are dropped.
    Radial { eval: fn(&[f64], f64) -> Radial, force: fn(&[f64], f64) -> f64, range: fn(&[f64]) -> f64 },
    /// E(r_i, r_j, r_k) for angles; positions are made image-consistent
    /// (r_i and r_k are placed at their minimum image around r_j).
    ThreeBody(fn(&[f64], [DVec3; 3]) -> ThreeBody),
    /// E(r) of one particle in an external field; r is the unwrapped position.
    OneBody(fn(&[f64], DVec3) -> OneBody),
    /// E(r_1 … r_n) of one closed surface: the evaluator gets the body's mesh
    /// and its node positions (image-consistent, local numbering), adds the
    /// force on each node to `forces` and returns the energy. The CPU backend
    /// evaluates it; `gpu` says how the GPU backend does ([`SurfaceGpu`],
    /// [`Law::runs_on_gpu`]). `hessian` gives the
    /// term's second-order model at x for the implicit step: local stencil
    /// Hessians (projected onto their PSD part by the backend) and
    /// Gauss–Newton rank-one terms ([`SurfaceHessian`]).
    Surface {
        eval: fn(params: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64,
        hessian: fn(params: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian),
        gpu: SurfaceGpu,
    },
    /// b(d) of the distance d from a node of one body to a face of another
    /// (E ≡ 0 for d ≥ `range`); the CPU backend finds the node–face pairs
    /// and spreads the force with [`node_face_forces`](super::node_face_forces); the GPU backend's
    /// contact kernel evaluates `shaders/interactions/NAME.wgsl` (src/gpu/contact.rs).
    Contact { eval: fn(&[f64], f64) -> Radial, range: fn(&[f64]) -> f64 },
    /// Adhesion-like terms weighted by area: E = ε·Σ_t A_t·s_a·s_b·s_c over
    /// the faces t of a body, ε = `density` (energy per area, negative for
    /// adhesion) and s_k = `switch`(d_k) ∈ [0, 1] of each corner, d_k its
    /// distance to the nearest face of another body the rule pairs it with
    /// (s ≡ 0 for d ≥ `range`): a face counts in proportion to how fully all
    /// three corners touch. The CPU backend finds the nearest faces (with the
    /// node–face candidates of [`Law::Contact`]) and adds both the area and
    /// the distance gradients; the GPU backend's area-weighted contact passes
    /// do the same on the device (src/gpu/adhesion.rs).
    ContactArea { switch: fn(&[f64], f64) -> Radial, density: fn(&[f64]) -> f64, range: fn(&[f64]) -> f64 },
    /// E(x_0 … x_3) of one linear tetrahedron with rest shape `TetraRest`;
    /// positions are image-consistent (around x_0). On the GPU its
    /// interaction's `NAME_tetra` evaluator gives W and P at F (src/gpu/tetra.rs).
    Tetra(fn(&[f64], &TetraRest, [DVec3; 4]) -> FourBody),
    /// A volume element whose volumetric energy lives on the nodes
    /// (average nodal pressure, `neo_hookean_anp`): `deviatoric` is the
    /// element's own energy V_0·W(F) without it, `volumetric` U(J) of a
    /// node's dilatation J_a = v_a/V_a (v_a, V_a: a quarter of the current
    /// and rest volumes of the node's elements of the same type), so that
    /// E = Σ_e V_0,e·W(F_e) + Σ_a V_a·U(J_a). The CPU backend averages the
    /// pressures U′(J_a) onto the elements (src/backend/nodal_pressure.rs);
    /// there is no GPU kernel ([`Law::runs_on_gpu`]).
    NodalTetra { deviatoric: fn(&[f64], &TetraRest, [DVec3; 4]) -> FourBody, volumetric: fn(&[f64], f64) -> Volumetric },
}

/// A law of one kind of term, taken out of its [`Law`] once when the term
/// is built (`forcefield::Typed`), so that the loops over terms of that kind
/// read it directly: `Kind` says where a type may be used, the law's type
/// says what evaluates it, and only that one place reconciles the two.
pub trait KindLaw: Copy + std::fmt::Debug {
    /// The law if `law` is of this family.
    fn from_law(law: Law) -> Option<Self>;
}

/// E(r) of a bond or a pair ([`Law::Radial`]).
#[derive(Clone, Copy, Debug)]
pub struct RadialLaw {
    pub eval: fn(&[f64], f64) -> Radial,
    pub force: fn(&[f64], f64) -> f64,
    pub range: fn(&[f64]) -> f64,
}

/// E(r_i, r_j, r_k) of an angle ([`Law::ThreeBody`]).
#[derive(Clone, Copy, Debug)]
pub struct AngleLaw(pub fn(&[f64], [DVec3; 3]) -> ThreeBody);

/// E(r) of one particle in an external field ([`Law::OneBody`]).
#[derive(Clone, Copy, Debug)]
pub struct ExternalLaw(pub fn(&[f64], DVec3) -> OneBody);

/// E of one closed surface ([`Law::Surface`]).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceLaw {
    pub eval: fn(params: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64,
    pub hessian: fn(params: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian),
    pub gpu: SurfaceGpu,
}

/// A term between bodies: node–face ([`Law::Contact`]) or area-weighted ([`Law::ContactArea`]).
#[derive(Clone, Copy, Debug)]
pub enum ContactLaw {
    NodeFace { eval: fn(&[f64], f64) -> Radial, range: fn(&[f64]) -> f64 },
    Area { switch: fn(&[f64], f64) -> Radial, density: fn(&[f64]) -> f64, range: fn(&[f64]) -> f64 },
}

/// E(x_0 … x_3) of a volume element ([`Law::Tetra`]), or its deviatoric
/// part and the nodal volumetric U(J) of a [`Law::NodalTetra`].
#[derive(Clone, Copy, Debug)]
pub struct TetraLaw {
    pub eval: fn(&[f64], &TetraRest, [DVec3; 4]) -> FourBody,
    pub volumetric: Option<fn(&[f64], f64) -> Volumetric>,
}

impl KindLaw for RadialLaw {
    fn from_law(law: Law) -> Option<Self> {
        match law {
            Law::Radial { eval, force, range } => Some(RadialLaw { eval, force, range }),
            _ => None,
        }
    }
}

impl KindLaw for AngleLaw {
    fn from_law(law: Law) -> Option<Self> {
        match law {
            Law::ThreeBody(eval) => Some(AngleLaw(eval)),
            _ => None,
        }
    }
}

impl KindLaw for ExternalLaw {
    fn from_law(law: Law) -> Option<Self> {
        match law {
            Law::OneBody(eval) => Some(ExternalLaw(eval)),
            _ => None,
        }
    }
}

impl KindLaw for SurfaceLaw {
    fn from_law(law: Law) -> Option<Self> {
        match law {
            Law::Surface { eval, hessian, gpu } => Some(SurfaceLaw { eval, hessian, gpu }),
            _ => None,
        }
    }
}

impl KindLaw for ContactLaw {
    fn from_law(law: Law) -> Option<Self> {
        match law {
            Law::Contact { eval, range } => Some(ContactLaw::NodeFace { eval, range }),
            Law::ContactArea { switch, density, range } => Some(ContactLaw::Area { switch, density, range }),
            _ => None,
        }
    }
}

impl ContactLaw {
    /// Beyond this distance the term is zero.
    pub fn range(&self, params: &[f64]) -> f64 {
        match self {
            ContactLaw::NodeFace { range, .. } | ContactLaw::Area { range, .. } => range(params),
        }
    }
}

impl KindLaw for TetraLaw {
    fn from_law(law: Law) -> Option<Self> {
        match law {
            Law::Tetra(eval) => Some(TetraLaw { eval, volumetric: None }),
            Law::NodalTetra { deviatoric, volumetric } => Some(TetraLaw { eval: deviatoric, volumetric: Some(volumetric) }),
            _ => None,
        }
    }
}

impl Law {
    /// Whether the GPU backend has a kernel for this law (and so its
    /// interaction a `shaders/interactions/NAME.wgsl` evaluator): every law
    /// but the surface laws without a GPU form (custom body terms) and the
    /// nodal-pressure volume elements.
    pub fn runs_on_gpu(&self) -> bool {
        match self {
            Law::Surface { gpu, .. } => *gpu != SurfaceGpu::None,
            Law::NodalTetra { .. } => false,
            _ => true,
        }
    }
}

/// How the GPU backend evaluates a surface law (src/gpu/surface.rs); the
/// law's `shaders/interactions/NAME.wgsl` defines the function named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceGpu {
    /// No kernel: the GPU backend refuses decks that use it (custom body terms).
    None,
    /// `NAME_face`: the forces on a face's corners from that face's corners
    /// and the body's totals (volume, area, face count).
    PerFace,
    /// `NAME_node`: an energy of each node's integrated mean curvature M_i
    /// and area A_i (sums over its edges and faces), with ∂E/∂M_i and ∂E/∂A_i.
    NodeCurvature,
}
