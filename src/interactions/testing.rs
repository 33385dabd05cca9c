//! Shared physics checks run on every interaction type.
//!
//! Each [`Law`] is viewed as a function of the positions of its particles,
//! E(r₁…rₙ) with forces f₁…fₙ, and checked for:
//! - F = −∇E by central differences (relative error < 1e-6 of the force scale);
//! - Σf = 0 and Σ r×f = 0 (momentum and angular momentum) when the law is internal;
//! - translation and rotation invariance of the energy (internal laws);
//! - zero force at the rest configuration the caller names;
//! - for [`Law::Radial`], d²E/dr² against a central difference of dE/dr, and
//!   the force-only evaluator (the step loop's) against `eval`'s dE/dr
//!   (forces in these checks come from `force`, energies from `eval`).
//!
//! A [`Law::Contact`] law is viewed as a function of four positions: the
//! node, then the three corners of the face.
//!
//! [`Law::Surface`] laws need a mesh besides positions: their checks are the
//! `assert_surface_*` functions, which run the same tests on a body.
//! [`Law::Tetra`] laws need a rest shape besides positions:
//! [`assert_tetra_checks`] runs the same tests on one element, and
//! [`assert_small_strain_moduli`] measures its Young's modulus and Poisson's
//! ratio by a small uniaxial stretch.
//! [`Law::ContactArea`] laws need whole bodies and their nearest faces: the
//! engine evaluates them, and [`assert_checks_of`] runs the same tests on
//! any energy-and-forces function of all positions (e.g. the CPU backend's).

use glam::{DMat3, DVec3};

pub use super::{Entry, Interaction};
use super::{FourBody, Law, SurfaceHessian, SurfaceMesh, TetraRest};
use crate::hessian::project_psd;
use faer::{Col, Mat};

/// Energy and per-particle forces of `law` at `positions` (1, 2 or 3
/// particles; 4 for a contact law: node, then the face's corners).
pub fn evaluate(law: Law, params: &[f64], positions: &[DVec3]) -> (f64, Vec<DVec3>) {
    match law {
        Law::Radial { eval, force, .. } => {
            // Energy from `eval`, forces from `force`: what the step loop uses.
            let d = positions[1] - positions[0];
            let f_i = d * force(params, d.length_squared());
            (eval(params, d.length()).energy, vec![f_i, -f_i])
        }
        Law::ThreeBody(eval) => {
            let out = eval(params, [positions[0], positions[1], positions[2]]);
            (out.energy, out.forces.to_vec())
        }
        Law::OneBody(eval) => {
            let out = eval(params, positions[0]);
            (out.energy, vec![out.force])
        }
        Law::Contact { eval, range } => {
            let pt = crate::mesh::point_triangle(positions[0], [positions[1], positions[2], positions[3]]);
            let out = if pt.distance < range(params) { eval(params, pt.distance) } else { super::Radial::ZERO };
            (out.energy, super::node_face_forces(&out, &pt).to_vec())
        }
        Law::Surface { .. } => panic!("a surface law needs its mesh: use evaluate_surface"),
        Law::ContactArea { .. } => panic!("an area-weighted contact law needs whole bodies: use assert_checks_of on the engine"),
        Law::Tetra(_) | Law::NodalTetra { .. } => panic!("a volume law needs its rest shape: use assert_tetra_checks"),
    }
}

/// Energy and per-node forces of a surface law on `mesh` at `positions`.
pub fn evaluate_surface(law: Law, params: &[f64], mesh: &SurfaceMesh, positions: &[DVec3]) -> (f64, Vec<DVec3>) {
    let Law::Surface { eval, .. } = law else { panic!("not a surface law") };
    let mut forces = vec![DVec3::ZERO; positions.len()];
    let energy = eval(params, mesh, positions, &mut forces);
    (energy, forces)
}

/// Resolves a name=value list against the schema, filling defaults.
pub fn params_of(interaction: &dyn Interaction, values: &[(&str, f64)]) -> Vec<f64> {
    let params: Vec<f64> = interaction
        .params()
        .iter()
        .map(|spec| {
            values
                .iter()
                .find(|(n, _)| *n == spec.name)
                .map(|(_, v)| *v)
                .or(spec.default)
                .unwrap_or_else(|| panic!("{}: test gives no `{}`", interaction.name(), spec.name))
        })
        .collect();
    for (spec, v) in interaction.params().iter().zip(&params) {
        spec.check(*v).unwrap();
    }
    interaction.validate(&params).unwrap();
    params
}

fn largest_force(forces: &[DVec3]) -> f64 {
    forces.iter().map(|f| f.length()).fold(0.0, f64::max)
}

/// Energy and forces as a function of all positions (one law, one term).
pub type EnergyAndForces<'a> = dyn Fn(&[DVec3]) -> (f64, Vec<DVec3>) + 'a;

fn force_is_minus_gradient(name: &str, eval: &EnergyAndForces, positions: &[DVec3], h: f64, force_floor: f64) {
    let (_, forces) = eval(positions);
    let scale = largest_force(&forces).max(force_floor);
    let mut plus = positions.to_vec();
    let mut minus = positions.to_vec();
    for (p, f) in forces.iter().enumerate() {
        for axis in 0..3 {
            plus[p][axis] += h;
            minus[p][axis] -= h;
            let numeric = -(eval(&plus).0 - eval(&minus).0) / (2.0 * h);
            plus[p][axis] = positions[p][axis];
            minus[p][axis] = positions[p][axis];
            let err = (numeric - f[axis]).abs() / scale;
            assert!(
                err < 1e-6,
                "{name}: F = -grad E fails on particle {p} axis {axis}: analytic {} numeric {numeric} (rel. err {err:e})",
                f[axis]
            );
        }
    }
}

fn momentum_conserved(name: &str, eval: &EnergyAndForces, positions: &[DVec3]) {
    let (_, forces) = eval(positions);
    let scale = largest_force(&forces).max(f64::MIN_POSITIVE);
    let sum: DVec3 = forces.iter().sum();
    assert!(sum.length() / scale < 1e-12, "{name}: sum of forces {sum:?}");
    let centre = positions.iter().sum::<DVec3>() / positions.len() as f64;
    let size = positions.iter().map(|p| (*p - centre).length()).fold(0.0, f64::max);
    let torque: DVec3 = positions.iter().zip(&forces).map(|(p, f)| (*p - centre).cross(*f)).sum();
    assert!(torque.length() / (scale * size) < 1e-12, "{name}: net torque {torque:?}");
}

fn invariant_under_rigid_motion(name: &str, eval: &EnergyAndForces, positions: &[DVec3]) {
    let (e0, f0) = eval(positions);
    let shift = DVec3::new(0.37, -1.21, 2.03);
    let rotation = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.813);
    let moved: Vec<DVec3> = positions.iter().map(|p| rotation * *p + shift).collect();
    let (e1, f1) = eval(&moved);
    let tol = 1e-12 * e0.abs().max(1.0);
    assert!((e1 - e0).abs() < tol, "{name}: energy changed under rigid motion: {e0} -> {e1}");
    let scale = largest_force(&f0).max(f64::MIN_POSITIVE);
    for (a, b) in f0.iter().zip(&f1) {
        assert!((rotation * *a - *b).length() / scale < 1e-10, "{name}: forces do not rotate with the system");
    }
}

fn zero_force_at_rest(name: &str, eval: &EnergyAndForces, rest: &[DVec3], force_scale: f64) {
    let (_, forces) = eval(rest);
    let worst = largest_force(&forces);
    assert!(worst <= 1e-9 * force_scale, "{name}: force {worst} at rest");
}

/// F = −∇E by central differences with step `h` (length units).
///
/// Passes when every component agrees to `1e-6 × max(|F|max, force_floor)`.
pub fn assert_force_is_minus_gradient(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3], h: f64, force_floor: f64) {
    let law = interaction.law();
    force_is_minus_gradient(interaction.name(), &|x| evaluate(law, params, x), positions, h, force_floor);
}

/// Σf = 0 and Σ r×f = 0 (internal forces conserve momentum and angular momentum).
pub fn assert_momentum_conserved(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3]) {
    let law = interaction.law();
    momentum_conserved(interaction.name(), &|x| evaluate(law, params, x), positions);
}

/// E is unchanged by a translation and by a rotation of all positions.
pub fn assert_invariant_under_rigid_motion(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3]) {
    let law = interaction.law();
    invariant_under_rigid_motion(interaction.name(), &|x| evaluate(law, params, x), positions);
}

/// All forces vanish at a rest configuration.
pub fn assert_zero_force_at_rest(interaction: &dyn Interaction, params: &[f64], rest: &[DVec3], force_scale: f64) {
    let law = interaction.law();
    zero_force_at_rest(interaction.name(), &|x| evaluate(law, params, x), rest, force_scale);
}

/// Every generic check of a surface law on one body: F = −∇E (central
/// differences, step `h`), Σf = 0, Σ r×f = 0, and invariance of E under a
/// translation and a rotation.
pub fn assert_surface_checks(
    interaction: &dyn Interaction,
    params: &[f64],
    mesh: &SurfaceMesh,
    positions: &[DVec3],
    h: f64,
    force_floor: f64,
) {
    let law = interaction.law();
    assert_checks_of(interaction.name(), &|x| evaluate_surface(law, params, mesh, x), positions, h, force_floor);
}

/// F = −∇E (central differences, step `h`), Σf = 0, Σ r×f = 0 and rigid-motion
/// invariance of any internal energy-and-forces function `eval` of all
/// positions (named `name` in messages): for many-body terms only the engine
/// evaluates, such as [`Law::ContactArea`].
pub fn assert_checks_of(name: &str, eval: &EnergyAndForces, positions: &[DVec3], h: f64, force_floor: f64) {
    force_is_minus_gradient(name, eval, positions, h, force_floor);
    momentum_conserved(name, eval, positions);
    invariant_under_rigid_motion(name, eval, positions);
}

/// All forces of a surface law vanish at a rest configuration of the body.
pub fn assert_surface_zero_force_at_rest(
    interaction: &dyn Interaction,
    params: &[f64],
    mesh: &SurfaceMesh,
    rest: &[DVec3],
    force_scale: f64,
) {
    let law = interaction.law();
    zero_force_at_rest(interaction.name(), &|x| evaluate_surface(law, params, mesh, x), rest, force_scale);
}

/// The second-order model of a surface law ([`SurfaceHessian`]) against
/// second differences of its energy (step `h`), on one body:
///
/// - its stencils and Gauss–Newton terms summed, unprojected, equal the Hessian
///   of E − `dropped` (the part of E whose curvature the model leaves out on
///   purpose, frozen at `positions`; zero for an exact model) to
///   `tolerance` × the largest entry;
/// - K̃ = Σ P(stencil) + Σ w·g gᵀ, with P the backend's PSD projection, is
///   positive semi-definite and K̃ ⪰ the unprojected sum (projection only
///   adds stiffness where a stencil is concave);
/// - K̃ annihilates rigid translations (no spurious stiffness).
///
/// Returns the smallest eigenvalue of the unprojected model over its largest
/// (negative when the law is concave somewhere, i.e. projection acted).
pub fn assert_surface_hessian(
    interaction: &dyn Interaction,
    params: &[f64],
    mesh: &SurfaceMesh,
    positions: &[DVec3],
    dropped: impl Fn(&[DVec3]) -> f64,
    h: f64,
    tolerance: f64,
) -> f64 {
    let name = interaction.name();
    let Law::Surface { eval, hessian, .. } = interaction.law() else { panic!("{name}: not a surface law") };
    let energy = |x: &[DVec3]| {
        let mut forces = vec![DVec3::ZERO; x.len()];
        eval(params, mesh, x, &mut forces) - dropped(x)
    };
    let dim = 3 * positions.len();
    let mut moved = positions.to_vec();
    let mut at = |shifts: &[(usize, f64)]| {
        for &(k, d) in shifts {
            moved[k / 3][k % 3] += d;
        }
        let e = energy(&moved);
        moved.copy_from_slice(positions);
        e
    };
    let e0 = at(&[]);
    let mut exact = Mat::<f64>::zeros(dim, dim);
    for k in 0..dim {
        exact[(k, k)] = (at(&[(k, h)]) - 2.0 * e0 + at(&[(k, -h)])) / (h * h);
        for l in 0..k {
            let mixed = at(&[(k, h), (l, h)]) - at(&[(k, h), (l, -h)]) - at(&[(k, -h), (l, h)]) + at(&[(k, -h), (l, -h)]);
            exact[(k, l)] = mixed / (4.0 * h * h);
            exact[(l, k)] = exact[(k, l)];
        }
    }
    let mut model = SurfaceHessian::default();
    hessian(params, mesh, positions, &mut model);
    let mut raw = Mat::<f64>::zeros(dim, dim);
    let mut projected = Mat::<f64>::zeros(dim, dim);
    for stencil in &model.stencils {
        let psd = project_psd(&stencil.matrix);
        for (a, &p) in stencil.nodes.iter().enumerate() {
            for (b, &q) in stencil.nodes.iter().enumerate() {
                for (r, c) in (0..9).map(|n| (n / 3, n % 3)) {
                    raw[(3 * p as usize + r, 3 * q as usize + c)] += stencil.matrix[(3 * a + r, 3 * b + c)];
                    projected[(3 * p as usize + r, 3 * q as usize + c)] += psd[(3 * a + r, 3 * b + c)];
                }
            }
        }
    }
    for term in &model.gauss_newton {
        assert!(term.weight >= 0.0, "{name}: Gauss–Newton weight {}", term.weight);
        for (&p, gp) in term.nodes.iter().zip(&term.gradient) {
            for (&q, gq) in term.nodes.iter().zip(&term.gradient) {
                for (r, c) in (0..9).map(|n| (n / 3, n % 3)) {
                    raw[(3 * p as usize + r, 3 * q as usize + c)] += term.weight * gp[r] * gq[c];
                    projected[(3 * p as usize + r, 3 * q as usize + c)] += term.weight * gp[r] * gq[c];
                }
            }
        }
    }
    for term in &model.rank_one {
        assert!(term.weight >= 0.0, "{name}: Gauss–Newton weight {}", term.weight);
        let g = Col::<f64>::from_fn(dim, |k| term.gradient[k / 3][k % 3]);
        let outer = term.weight * &g * g.transpose();
        raw += &outer;
        projected += &outer;
    }
    let scale = (0..dim).flat_map(|r| (0..dim).map(move |c| (r, c))).map(|(r, c)| exact[(r, c)].abs()).fold(0.0, f64::max);
    let error = (0..dim).flat_map(|r| (0..dim).map(move |c| (r, c))).map(|(r, c)| (raw[(r, c)] - exact[(r, c)]).abs()).fold(0.0, f64::max);
    assert!(error < tolerance * scale, "{name}: model Hessian differs from second differences of E by {error:e} (largest entry {scale:e})");
    let eigenvalues = |m: &Mat<f64>| m.self_adjoint_eigenvalues(faer::Side::Lower).expect("symmetric eigenvalues");
    let lowest = eigenvalues(&projected)[0];
    assert!(lowest > -1e-9 * scale, "{name}: K̃ has a negative eigenvalue {lowest:e} (largest entry {scale:e})");
    let excess = eigenvalues(&(&projected - &raw))[0];
    assert!(excess > -1e-9 * scale, "{name}: K̃ − H has a negative eigenvalue {excess:e}: projection removed stiffness");
    for axis in 0..3 {
        let shift = Col::<f64>::from_fn(dim, |k| f64::from(u8::from(k % 3 == axis)));
        let residual = (&projected * &shift).norm_l2();
        assert!(residual < tolerance * scale * shift.norm_l2(), "{name}: K̃ resists a translation along axis {axis}: |K̃·t| = {residual:e}");
    }
    let spectrum = eigenvalues(&raw);
    spectrum[0] / spectrum[dim - 1]
}

/// The surface-law test meshes: [`deformed_icosphere`] of radius 1.5 and
/// jitter 0.05 at each of `levels`, with its level.
pub fn deformed_icospheres(levels: &[u32]) -> impl Iterator<Item = (u32, SurfaceMesh, Vec<DVec3>)> + '_ {
    levels.iter().map(|&level| {
        let (mesh, x) = deformed_icosphere(level, 1.5, 0.05);
        (level, mesh, x)
    })
}

/// A deformed icosphere for surface-law tests: the icosphere of `level` and
/// `radius`, stretched into an ellipsoid (1.3, 1, 0.8) and each node moved
/// by a deterministic pseudo-random offset of up to `jitter` × radius.
pub fn deformed_icosphere(level: u32, radius: f64, jitter: f64) -> (SurfaceMesh, Vec<DVec3>) {
    let (x, faces) = crate::mesh::icosphere(level, radius);
    let x = x
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let k = k as f64;
            let noise = DVec3::new((12.9898 * k).sin(), (78.233 * k + 1.0).sin(), (37.719 * k + 2.0).sin());
            DVec3::new(1.3 * p.x, p.y, 0.8 * p.z) + jitter * radius * noise
        })
        .collect();
    (SurfaceMesh::new(x_len(&faces), faces).expect("an icosphere is a closed mesh"), x)
}

fn x_len(faces: &[[u32; 3]]) -> usize {
    faces.iter().flatten().map(|&p| p as usize + 1).max().unwrap_or(0)
}

/// For a radial or contact law, d²E/dr² (s″ of an area-weighted law's switch) matches a central difference of dE/dr at `r`.
pub fn assert_radial_curvature(interaction: &dyn Interaction, params: &[f64], r: f64, h: f64) {
    let (Law::Radial { eval, .. } | Law::Contact { eval, .. } | Law::ContactArea { switch: eval, .. }) = interaction.law() else {
        panic!("{} is not radial", interaction.name())
    };
    let numeric = (eval(params, r + h).de_dr - eval(params, r - h).de_dr) / (2.0 * h);
    let analytic = eval(params, r).d2e_dr2;
    let scale = analytic.abs().max(numeric.abs()).max(1e-300);
    assert!((analytic - numeric).abs() / scale < 1e-5, "{}: d2E/dr2 at r = {r}: analytic {analytic} numeric {numeric}", interaction.name());
}

/// Runs every generic check appropriate to the law at `positions`.
///
/// `internal` is false for external fields (which need not conserve momentum).
pub fn assert_all_checks(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3], h: f64, force_floor: f64) {
    assert_force_is_minus_gradient(interaction, params, positions, h, force_floor);
    if !matches!(interaction.law(), Law::OneBody(_) | Law::Surface { .. }) {
        assert_momentum_conserved(interaction, params, positions);
        assert_invariant_under_rigid_motion(interaction, params, positions);
    }
    if matches!(interaction.law(), Law::Radial { .. }) {
        let r = (positions[1] - positions[0]).length();
        assert_radial_curvature(interaction, params, r, h);
        assert_force_matches_eval(interaction, params, r);
    }
}

/// For a radial law, `force(p, r²)·r` (the step loop's force) equals
/// `eval(p, r).de_dr` to rounding (the same derivative, computed without the energy).
pub fn assert_force_matches_eval(interaction: &dyn Interaction, params: &[f64], r: f64) {
    let Law::Radial { eval, force, .. } = interaction.law() else { panic!("{} is not radial", interaction.name()) };
    let (de_dr, fast) = (eval(params, r).de_dr, force(params, r * r) * r);
    let scale = de_dr.abs().max(fast.abs()).max(1e-300);
    assert!((de_dr - fast).abs() / scale < 1e-12, "{}: at r = {r}: force·r = {fast}, eval dE/dr = {de_dr}", interaction.name());
}

/// The unit right tetrahedron (corners 0, x̂, ŷ, ẑ: D_m = I, V_0 = 1/6) stretched by F = diag(s, t, t).
pub fn stretched_unit_tetra(s: f64, t: f64) -> [DVec3; 4] {
    [DVec3::ZERO, s * DVec3::X, t * DVec3::Y, t * DVec3::Z]
}

/// The rest shape of the unit right tetrahedron.
pub fn unit_tetra_rest() -> TetraRest {
    TetraRest::new(stretched_unit_tetra(1.0, 1.0)).unwrap()
}

/// (rest, current) corners of skewed tetrahedra under stretch, shear,
/// compression and a large rotation, in both windings.
pub fn deformed_tetrahedra() -> Vec<([DVec3; 4], [DVec3; 4])> {
    let rest = [DVec3::new(0.1, -0.2, 0.05), DVec3::new(0.9, 0.1, -0.1), DVec3::new(0.2, 0.8, 0.15), DVec3::new(0.3, 0.25, 0.7)];
    let mirrored = [rest[0], rest[2], rest[1], rest[3]];
    let spin = glam::DQuat::from_axis_angle(DVec3::new(0.3, -1.0, 0.4).normalize(), 2.3);
    let maps: [DMat3; 3] = [
        DMat3::from_cols(DVec3::new(1.2, 0.1, 0.0), DVec3::new(-0.05, 0.9, 0.2), DVec3::new(0.0, 0.1, 1.05)),
        DMat3::from_cols(DVec3::new(0.7, 0.0, 0.1), DVec3::new(0.3, 0.8, 0.0), DVec3::new(0.0, -0.2, 0.6)),
        DMat3::from_quat(spin) * DMat3::from_diagonal(DVec3::new(1.4, 0.8, 0.95)),
    ];
    let mut out = Vec::new();
    for r in [rest, mirrored] {
        for m in maps {
            out.push((r, r.map(|x| m * x + DVec3::new(0.3, -0.1, 0.2))));
        }
    }
    out
}

/// A volume law's energy and forces of one element alone (a
/// [`Law::NodalTetra`] with its nodal volumes those of the element:
/// [`nodal_tetra_alone`](super::nodal_tetra_alone)).
pub fn element_law(interaction: &dyn Interaction) -> impl Fn(&[f64], &TetraRest, [DVec3; 4]) -> FourBody {
    let law = interaction.law();
    move |p, rest, x| match law {
        Law::Tetra(eval) => eval(p, rest, x),
        Law::NodalTetra { deviatoric, volumetric } => super::nodal_tetra_alone(deviatoric, volumetric, p, rest, x),
        _ => panic!("not a volume law"),
    }
}

/// F = −∇E, Σf = 0, Σ r×f = 0 and rigid-motion invariance of a volume law on
/// one element with rest corners `rest` at corners `x`, and zero force at rest.
pub fn assert_tetra_checks(interaction: &dyn Interaction, params: &[f64], rest: [DVec3; 4], x: [DVec3; 4], h: f64, force_floor: f64) {
    let eval = element_law(interaction);
    let shape = TetraRest::new(rest).unwrap();
    let element = |p: &[DVec3]| {
        let out = eval(params, &shape, [p[0], p[1], p[2], p[3]]);
        (out.energy, out.forces.to_vec())
    };
    assert_checks_of(interaction.name(), &element, &x, h, force_floor);
    zero_force_at_rest(interaction.name(), &element, &rest, force_floor);
}

/// The analytic oracle of a volume law with parameters `e` and `nu`: a uniaxial
/// stretch ε = 10⁻⁵ of the unit right tetrahedron, its lateral stretch t
/// found by bisection where the lateral stress vanishes, gives the nominal
/// stress P₁₁ = E·ε and t = 1 − ν·ε (relative 10⁻³ for E, 10⁻³ for ν).
pub fn assert_small_strain_moduli(interaction: &dyn Interaction, params: &[f64]) {
    let eval = element_law(interaction);
    let (e, nu) = (params[0], params[1]);
    let (rest, eps) = (unit_tetra_rest(), 1e-5);
    let lateral = |t: f64| eval(params, &rest, stretched_unit_tetra(1.0 + eps, t)).forces[2].y;
    let (mut lo, mut hi) = (1.0 - eps, 1.0 + eps);
    assert!(lateral(lo) > 0.0 && lateral(hi) < 0.0, "{}: the lateral stress does not change sign", interaction.name());
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if lateral(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    let p11 = -eval(params, &rest, stretched_unit_tetra(1.0 + eps, t)).forces[1].x * 6.0;
    let (young, poisson) = (p11 / eps, (1.0 - t) / eps);
    assert!((young - e).abs() < 1e-3 * e, "{}: Young's modulus {young}, expected {e}", interaction.name());
    assert!((poisson - nu).abs() < 1e-3, "{}: Poisson's ratio {poisson}, expected {nu}", interaction.name());
}

/// Every shared check of a volume law (parameters `e`, `nu`) at a stiff, a
/// nearly incompressible and an auxetic material: [`assert_tetra_checks`]
/// on [`deformed_tetrahedra`] and [`assert_small_strain_moduli`].
pub fn assert_volume_law_checks(interaction: &dyn Interaction) {
    for (e, nu) in [(1000.0, 0.3), (250.0, 0.49), (40.0, -0.2)] {
        let p = params_of(interaction, &[("e", e), ("nu", nu)]);
        for (rest, x) in deformed_tetrahedra() {
            assert_tetra_checks(interaction, &p, rest, x, 1e-6, 1e-3 * e);
        }
        assert_small_strain_moduli(interaction, &p);
    }
}
