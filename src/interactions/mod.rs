//! The interaction registry: every mechanism is one registered interaction type.
//!
//! An interaction type declares its name (its force-field keyword, the stem of
//! its `.rs`, `.md`, `.wgsl` and reference `.yaml` files), its [`Kind`], its
//! parameter schema ([`ParamSpec`]: name, unit, allowed range, default, doc),
//! and a [`Law`]: the evaluator that turns parameters and geometry into energy
//! and forces. Loops over terms, periodic images, neighbour lists and force
//! accumulation live once in the backend; an interaction file holds only its
//! functional form (HOOMD-blue's evaluator pattern).
//!
//! Name, summary, Markdown page and schema make an interaction type a
//! documented registry [`Entry`], the trait kinetic rules share; `cellmd list
//! NAME` prints [`documentation`] of either.
//!
//! Parameters reach an evaluator as a slice in schema order, already checked
//! against the schema and by [`Entry::validate`].
//!
//! Many-body terms of closed surfaces (cell shells) use [`Law::Surface`]: the
//! evaluator sees one body's whole mesh ([`SurfaceMesh`]) with image-consistent
//! node positions and adds a force to every node; the backend evaluates each
//! body once per force pass into per-node slots that each particle gathers.
//!
//! Contact between different bodies uses [`Law::Contact`]: an energy b(d) of
//! the distance d from a node of one body to a face of another
//! ([`crate::mesh::point_triangle`]), spread onto the node and the face's
//! corners by [`node_face_forces`]. Adhesion uses [`Law::ContactArea`]: an
//! energy per unit area of each face, switched on by its corners' distances
//! to the nearest face of another body.
//!
//! Volume elements use [`Law::Tetra`]: an energy V_0·W(F) of one linear
//! tetrahedron, W a strain-energy density of its deformation gradient F
//! relative to its rest shape ([`TetraRest`], from the topology's initial
//! positions); [`elastic_tetra`] turns W and its stress into corner forces.
//! [`Law::NodalTetra`] moves the volumetric part onto the nodes (average
//! nodal pressure, locking-free as ν → 0.5).
//!
//! Laws carry what later solvers need: [`Radial`] returns d²E/dr², from which
//! the analytic pair Hessian `E''·ûûᵀ + (E'/r)(I − ûûᵀ)` follows; state that
//! changes during a run (e.g. a rest length under kinetics) is a parameter
//! value, so a stateful bond owns its own parameter copy.

use glam::{DMat3, DVec3};

pub(crate) use self::entry::entry;
pub use self::entry::{documentation, Bound, Entry, ParamSpec};
pub use self::law::{AngleLaw, ContactLaw, ExternalLaw, KindLaw, Law, RadialLaw, SurfaceGpu, SurfaceLaw, TetraLaw};
pub use self::wall::plane as wall_plane;
pub use crate::hessian::SurfaceHessian;
pub use crate::mesh::{SurfaceMesh, TetraRest};
use crate::units::Dim;

/// Implements [`Entry`] and [`Interaction`] for a unit struct from its
/// registration data: the name (also the stem of its `.md` doc file), kind,
/// one-line summary, the module's `PARAMS` schema, its law, and optionally a
/// `validate` function and a `lammps` translation ([`Interaction::lammps`]).
macro_rules! interaction {
    ($ty:ident, $name:literal, $kind:expr, $summary:literal, $law:expr $(, validate = $validate:path)? $(, lammps = $lammps:path)? $(, fibre_bending = $bending:path)?) => {
        $crate::interactions::entry!($ty, $name, $kind.keyword(), $summary $(, validate = $validate)?);

        impl $crate::interactions::Interaction for $ty {
            fn kind(&self) -> $crate::interactions::Kind {
                $kind
            }
            fn law(&self) -> $crate::interactions::Law {
                $law
            }
            $(fn lammps(&self, term: &$crate::interactions::lammps::LammpsTerm) -> $crate::interactions::lammps::Translation {
                $lammps(term)
            })?
            $(fn fibre_bending(&self, params: &[f64]) -> Option<f64> {
                Some($bending(params))
            })?
        }
    };
}

/// The `force` of a [`Law::Radial`] from its `eval` (for laws that need r
/// anyway): `over_r(eval(p, √r²).de_dr, √r²)`. `eval` is inlined into the
/// closure, so the energy and d²E/dr² it would compute are dropped.
macro_rules! radial_force {
    ($eval:ident) => {
        |p: &[f64], r2: f64| {
            let r = r2.sqrt();
            $crate::interactions::over_r($eval(p, r).de_dr, r)
        }
    };
}

pub mod custom;
mod entry;
pub mod lammps;
mod law;
pub mod testing;

mod area_conservation;
mod asymmetric;
mod cable;
mod constant_force;
mod contact_adhesion;
mod contact_barrier;
mod cosine_angle;
mod fene;
mod field;
mod flat_punch;
mod harmonic;
mod harmonic_angle;
mod helfrich_bending;
mod indenter;
mod linear_elastic;
mod lj;
mod neo_hookean;
mod neo_hookean_anp;
mod soft;
mod soft_repulsion;
mod spring;
mod surface_shear;
mod surface_tension;
mod turgor;
mod turgor_log;
mod wall;
mod wca;
mod wlc_bending;

/// Every registered interaction type. The parser, validator, `cellmd list`
/// and the docs read this list; nothing else lists interaction names.
pub static REGISTRY: &[&dyn Interaction] = &[
    &harmonic::Harmonic,
    &fene::Fene,
    &cable::Cable,
    &spring::Spring,
    &asymmetric::Asymmetric,
    &wlc_bending::WlcBending,
    &harmonic_angle::HarmonicAngle,
    &cosine_angle::CosineAngle,
    &soft_repulsion::SoftRepulsion,
    &lj::Lj,
    &wca::Wca,
    &soft::Soft,
    &wall::Wall,
    &constant_force::ConstantForce,
    &indenter::Indenter,
    &flat_punch::FlatPunch,
    &field::Field,
    &turgor::Turgor,
    &turgor_log::TurgorLog,
    &surface_tension::SurfaceTension,
    &area_conservation::AreaConservation,
    &surface_shear::SurfaceShear,
    &helfrich_bending::HelfrichBending,
    &contact_barrier::ContactBarrier,
    &contact_adhesion::ContactAdhesion,
    &neo_hookean::NeoHookean,
    &neo_hookean_anp::NeoHookeanAnp,
    &linear_elastic::LinearElastic,
    &custom::Custom,
];

/// Looks an interaction type up by its registered name.
pub fn lookup(name: &str) -> Option<&'static dyn Interaction> {
    REGISTRY.iter().copied().find(|i| i.name() == name)
}

/// Where an interaction type may be used in a force field or deck.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Two-particle bonded term (`bond` lines).
    Bond,
    /// Three-particle bonded term (`angle` lines).
    Angle,
    /// Non-bonded pair term by type pair, within a cutoff (`pair` lines).
    Pair,
    /// One-particle external field on a group (deck `external` command).
    External,
    /// Many-body term of a closed surface, by body type (`body` lines).
    Body,
    /// Node–face term between different bodies, by body-type pair (`contact` lines).
    Contact,
    /// Four-particle volume element (`tetra` lines, `[ tetrahedra ]` of the topology).
    Tetra,
}

impl Kind {
    /// The keyword that introduces this kind in a force-field file or deck.
    pub fn keyword(self) -> &'static str {
        match self {
            Kind::Bond => "bond",
            Kind::Angle => "angle",
            Kind::Pair => "pair",
            Kind::External => "external",
            Kind::Body => "body",
            Kind::Contact => "contact",
            Kind::Tetra => "tetra",
        }
    }

    /// The kind a force-field or deck keyword introduces.
    pub fn from_keyword(word: &str) -> Option<Kind> {
        [Kind::Bond, Kind::Angle, Kind::Pair, Kind::External, Kind::Body, Kind::Contact, Kind::Tetra]
            .into_iter()
            .find(|k| k.keyword() == word)
    }

    /// "a bond", "an angle", … for messages.
    pub fn with_article(self) -> &'static str {
        match self {
            Kind::Bond => "a bond",
            Kind::Angle => "an angle",
            Kind::Pair => "a pair",
            Kind::External => "an external",
            Kind::Body => "a body",
            Kind::Contact => "a contact",
            Kind::Tetra => "a tetra",
        }
    }
}

/// Energy and its radial derivatives for a law that depends only on the
/// distance r between two particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radial {
    pub energy: f64,
    /// dE/dr: positive when the pair pulls together (tension).
    pub de_dr: f64,
    /// d²E/dr², for analytic Jacobians.
    pub d2e_dr2: f64,
}

impl Radial {
    pub const ZERO: Radial = Radial { energy: 0.0, de_dr: 0.0, d2e_dr2: 0.0 };

    /// The force on the particle at the origin of `d` (the separation to its
    /// partner, length `r`): `(dE/dr)·d/r`. A term that exerts no force gives
    /// exactly zero, even for coincident particles (r = 0), where `d/r` is
    /// undefined: a slack cable between two particles that met is no blow-up.
    #[inline(always)]
    pub fn force_along(&self, d: DVec3, r: f64) -> DVec3 {
        if self.de_dr == 0.0 {
            DVec3::ZERO
        } else {
            d * (self.de_dr / r)
        }
    }
}

/// (dE/dr)/r, exactly 0 when dE/dr = 0 (even at r = 0; see [`Radial::force_along`]).
#[inline(always)]
pub fn over_r(de_dr: f64, r: f64) -> f64 {
    if de_dr == 0.0 {
        0.0
    } else {
        de_dr / r
    }
}

/// Energy and the force on each of three particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThreeBody {
    pub energy: f64,
    pub forces: [DVec3; 3],
}

/// Energy and the force on each corner of a tetrahedron.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FourBody {
    pub energy: f64,
    pub forces: [DVec3; 4],
}

/// The energy V_0·W(F) and corner forces of a volume element, from
/// `density(F, J)` = (W, P) (strain-energy density and first Piola stress at
/// F, J = det F > 0). An element turned inside out or flat (J ≤ 0), where no
/// elastic law is defined, gets a NaN energy and NaN forces: the run stops
/// with a blow-up report that names the element and its term.
pub fn elastic_tetra(rest: &TetraRest, x: [DVec3; 4], density: impl FnOnce(DMat3, f64) -> (f64, DMat3)) -> FourBody {
    let f = rest.deformation_gradient(x);
    let j = f.determinant();
    if !(j > 0.0) {
        return FourBody { energy: f64::NAN, forces: [DVec3::NAN; 4] };
    }
    let (w, piola) = density(f, j);
    FourBody { energy: rest.volume * w, forces: rest.forces(piola) }
}

/// The parameters of the isotropic elastic volume laws: Young's modulus and Poisson's ratio.
pub(crate) static ELASTIC_PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("e", Dim::Pressure, "Young's modulus E (pN/µm² = Pa in cell units)").positive(),
    ParamSpec {
        min: Bound::Exclusive(-1.0),
        ..ParamSpec::new(
            "nu",
            Dim::Dimensionless,
            "Poisson's ratio ν; up to 0.5 (exclusive): nearly incompressible is allowed, but linear tetrahedra lock as ν → 0.5",
        )
        .below(0.5)
    },
];

/// Lamé's constants (μ, λ) = (E/(2(1 + ν)), Eν/((1 + ν)(1 − 2ν))) of `ELASTIC_PARAMS` values.
pub fn lame(p: &[f64]) -> (f64, f64) {
    let (e, nu) = (p[0], p[1]);
    (e / (2.0 * (1.0 + nu)), e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)))
}

/// Energy and force of a one-particle external field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneBody {
    pub energy: f64,
    pub force: DVec3,
}

/// A volumetric energy density U(J) per unit rest volume and its
/// derivatives: `pressure` U′(J), `stiffness` U″(J).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volumetric {
    pub energy: f64,
    pub pressure: f64,
    pub stiffness: f64,
}

/// A volume element's energy and forces with the pressure `pressure` added
/// to its `deviatoric` part: the forces −p·∂v/∂x of its current volume
/// v = J·V_0 (Piola stress p·J·F⁻ᵀ, J·F⁻ᵀ the cofactor of F), its energy
/// unchanged (the caller adds the volumetric energy). A flat or inverted
/// element (J ≤ 0) has NaN forces, as in [`elastic_tetra`].
pub fn pressured_tetra(rest: &TetraRest, x: [DVec3; 4], deviatoric: FourBody, pressure: f64) -> FourBody {
    let f = rest.deformation_gradient(x);
    let j = f.determinant();
    if !(j > 0.0) {
        return FourBody { energy: f64::NAN, forces: [DVec3::NAN; 4] };
    }
    let volumetric = rest.forces(pressure * j * f.inverse().transpose());
    FourBody { energy: deviatoric.energy, forces: std::array::from_fn(|k| deviatoric.forces[k] + volumetric[k]) }
}

/// A [`Law::NodalTetra`] element alone (its nodes shared with no other
/// element, so J_a = J at each corner): V_0·(W(F) + U(J)) and its forces.
pub fn nodal_tetra_alone(
    deviatoric: fn(&[f64], &TetraRest, [DVec3; 4]) -> FourBody,
    volumetric: fn(&[f64], f64) -> Volumetric,
    params: &[f64],
    rest: &TetraRest,
    x: [DVec3; 4],
) -> FourBody {
    let j = rest.deformation_gradient(x).determinant();
    let u = volumetric(params, j);
    let out = pressured_tetra(rest, x, deviatoric(params, rest, x), u.pressure);
    FourBody { energy: out.energy + rest.volume * u.energy, ..out }
}

/// Forces [node, corner 0, corner 1, corner 2] of a node–face energy b(d) with
/// db/dd = `radial.de_dr` at the closest point `pt`: −b′·∂d/∂x, i.e.
/// −b′·n̂ on the node and +b′·w_k·n̂ on corner k (they sum to zero, and exert
/// no torque since all act along n̂ through the line p–q).
#[inline]
pub fn node_face_forces(radial: &Radial, pt: &crate::mesh::PointTriangle) -> [DVec3; 4] {
    let g = radial.de_dr * pt.normal;
    [-g, pt.weights[0] * g, pt.weights[1] * g, pt.weights[2] * g]
}

/// A registered interaction type.
/// Its [`Entry`] doc has the headings Potential, References, Example.
pub trait Interaction: Entry {
    fn kind(&self) -> Kind;
    fn law(&self) -> Law;
    /// The energy expression of a [`custom`] law (for translations to other
    /// engines); `None` for the registered laws.
    fn expression(&self) -> Option<&crate::expr::Expr> {
        None
    }
    /// How LAMMPS writes a term of this type (module [`lammps`]); `None`
    /// (the default) when it has no equivalent.
    fn lammps(&self, _term: &lammps::LammpsTerm) -> lammps::Translation {
        None
    }
    /// For an angle law of the fibre-bending form E = s·(1 − t₁·t₂) (t₁, t₂
    /// the unit tangents of the two arms, in chain order): s, so that the
    /// fibre solver (`integrate::fibre`) can carry the joint in a fibre's
    /// banded block; `None` (the default) for every other law.
    fn fibre_bending(&self, _params: &[f64]) -> Option<f64> {
        None
    }
}

/// Index of a parameter in an interaction's schema.
pub fn param_index(interaction: &dyn Interaction, name: &str) -> Option<usize> {
    interaction.params().iter().position(|p| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_snake_case_and_have_their_doc_file() {
        let mut seen = std::collections::HashSet::new();
        for i in REGISTRY {
            assert!(seen.insert(i.name()), "duplicate {}", i.name());
            assert!(i.name().chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_'), "{} is not snake_case", i.name());
            let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/src/interactions/");
            for ext in ["rs", "md"] {
                let path = format!("{dir}{}.{ext}", i.name());
                assert!(std::path::Path::new(&path).exists(), "missing {path}");
            }
        }
        // and no interaction file without a registry entry
        for entry in std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/src/interactions")).unwrap() {
            let path = entry.unwrap().path();
            let stem = path.file_stem().unwrap().to_str().unwrap().to_string();
            if ["mod", "entry", "law", "lammps", "testing"].contains(&stem.as_str()) {
                continue;
            }
            assert!(lookup(&stem).is_some(), "{} has no REGISTRY entry", path.display());
        }
    }

    #[test]
    fn every_doc_has_the_house_headings_and_params_have_docs() {
        for i in REGISTRY {
            for heading in ["## Potential", "## References", "## Example"] {
                assert!(i.doc().contains(heading), "{} doc lacks {heading}", i.name());
            }
            assert!(!i.summary().is_empty());
            for p in i.params() {
                assert!(!p.doc.is_empty(), "{}.{} undocumented", i.name(), p.name);
                if let Some(d) = p.default {
                    p.check(d).unwrap_or_else(|e| panic!("{}: default violates range: {e}", i.name()));
                }
            }
            // Kind and law agree.
            match (i.kind(), i.law()) {
                (Kind::Bond | Kind::Pair, Law::Radial { .. })
                | (Kind::Angle, Law::ThreeBody(_))
                | (Kind::External, Law::OneBody(_))
                | (Kind::Body, Law::Surface { .. })
                | (Kind::Contact, Law::Contact { .. } | Law::ContactArea { .. })
                | (Kind::Tetra, Law::Tetra(_) | Law::NodalTetra { .. }) => {}
                _ => panic!("{}: kind and law disagree", i.name()),
            }
        }
    }

    #[test]
    fn range_check_rejects_nan_and_out_of_range() {
        let p = ParamSpec::new("k", Dim::Stiffness, "spring constant").positive();
        assert!(p.check(1.0).is_ok());
        assert!(p.check(0.0).unwrap_err().contains("> 0"));
        assert!(p.check(f64::NAN).is_err());
        let q = ParamSpec::new("tau", Dim::Dimensionless, "x").non_negative().below(1.0);
        assert_eq!(q.range_text(), "in [0, 1)");
    }
}
