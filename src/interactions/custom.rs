#![doc = include_str!("custom.md")]
//!
//! # Implementation
//!
//! A `custom` line builds a [`CustomLaw`]: the energy's tree, its symbolic
//! derivatives ([`Expr::derivative`]) and their compiled tapes
//! ([`crate::expr::tape`]). Laws are plain `fn` pointers that receive only
//! the term's parameter vector, so a custom term's vector carries its tapes:
//! `[parameter values…, tape words…, trailer]`, the trailer being the start of
//! each tape (see `laws::tape_of`). One evaluator per law family reads them; the
//! parameter values come first, in declaration order, so `coeff` and kinetic
//! rules (`r0`) edit them like any law's. [`CustomLaw`]s are made once per
//! force-field line and live for the program (as registered laws do).
//!
//! The registry holds one entry, [`Custom`], named `custom` (for `cellmd
//! list custom` and per-interaction energy accounting, `pe/custom`); it is
//! the body-term evaluator with no parameters of its own.

mod laws;
mod lepton;

use self::laws::{angle_eval, body_eval, body_hessian, external_eval, pair_eval, pair_force, radial_eval, radial_force};
use super::lammps::{bonded, lepton_bond, num, pair, LammpsStyle, LammpsTerm, Translation};
use super::{Entry, Interaction, Kind, Law, ParamSpec, SurfaceGpu};
use crate::expr::tape::{compile, Slot};
use crate::expr::{parse, Expr, ExprError, Span};
use crate::units::Dim;

/// The variables an expression of each kind may read, and their meaning.
pub fn variables(kind: Kind) -> &'static [(&'static str, &'static str)] {
    match kind {
        Kind::Bond | Kind::Pair => &[("r", "distance between the two particles (length)")],
        Kind::Angle => &[("theta", "angle at the middle particle, in radians (0 to π)")],
        Kind::External => &[("x", "position x"), ("y", "position y"), ("z", "position z"), ("t", "time")],
        Kind::Body => &[("V", "enclosed volume of the body"), ("A", "surface area of the body")],
        Kind::Contact | Kind::Tetra => &[],
    }
}

/// A declared parameter of a custom law.
#[derive(Clone, Debug)]
pub struct Declared {
    pub name: String,
    pub dim: Dim,
}

/// What is wrong with a custom law, and where.
#[derive(Clone, Debug, PartialEq)]
pub enum CustomError {
    /// At a span of the expression text.
    Expression(ExprError),
    /// At the declaration of parameter `index`.
    Parameter { index: usize, message: String },
}

/// A custom interaction: one force-field line's expression and parameters.
pub struct CustomLaw {
    kind: Kind,
    text: String,
    energy: Expr,
    specs: &'static [ParamSpec],
    /// Everything after the parameter values: tapes and trailer.
    tapes: Vec<f64>,
}

/// The first declared parameter of a pair law: its cutoff.
pub const CUTOFF: &str = "cutoff";

impl CustomLaw {
    /// Parses and compiles `text` as the energy of a `kind` term with
    /// parameters `declared` (for a pair, the first is the [`CUTOFF`]).
    /// Every parameter must appear in the expression (the cutoff may not),
    /// and every name the expression reads must be a variable of the kind or
    /// a parameter.
    pub fn new(kind: Kind, text: &str, declared: &[Declared]) -> Result<&'static CustomLaw, CustomError> {
        let vars = variables(kind);
        if vars.is_empty() {
            return Err(CustomError::Expression(ExprError::new(
                Span { start: 0, end: text.len() },
                format!("found a custom {} law, expected one of the kinds bond, angle, pair, external or body", kind.keyword()),
            )));
        }
        for (index, d) in declared.iter().enumerate() {
            let clash = if vars.iter().any(|(v, _)| *v == d.name) {
                Some(format!("`{}` is a variable of {} expression", d.name, kind.with_article()))
            } else if d.name == "pi" {
                Some("`pi` is the number π".to_string())
            } else if declared[..index].iter().any(|o| o.name == d.name) {
                Some(format!("parameter `{}` is declared twice", d.name))
            } else {
                None
            };
            if let Some(why) = clash {
                return Err(CustomError::Parameter { index, message: format!("{why}; expected another parameter name") });
            }
        }
        let energy = parse(text).map_err(CustomError::Expression)?;
        let names: Vec<&str> = declared.iter().map(|d| d.name.as_str()).collect();
        for (r, span) in energy.refs() {
            let known = match r {
                crate::expr::Ref::Name(n) => vars.iter().any(|(v, _)| *v == n) || names.contains(&n),
                crate::expr::Ref::Thermo(_) | crate::expr::Ref::Previous(_) => false,
            };
            if !known {
                let listed: Vec<&str> = vars.iter().map(|(v, _)| *v).chain(names.iter().copied()).collect();
                let found = r.quoted();
                return Err(CustomError::Expression(ExprError::new(
                    span,
                    format!(
                        "found unknown symbol {found}, expected a variable of {} or a declared parameter: {}",
                        kind.with_article(),
                        listed.join(", ")
                    ),
                )));
            }
        }
        for (index, d) in declared.iter().enumerate() {
            if !(energy.depends_on(&d.name) || kind == Kind::Pair && index == 0) {
                return Err(CustomError::Parameter {
                    index,
                    message: format!("parameter `{}` is not used in the expression; expected every declared parameter in it", d.name),
                });
            }
        }
        let mut specs: Vec<ParamSpec> = declared
            .iter()
            .enumerate()
            .map(|(index, d)| {
                let name: &'static str = Box::leak(d.name.clone().into_boxed_str());
                let spec = ParamSpec::new(name, d.dim, "parameter of the expression");
                if kind == Kind::Pair && index == 0 {
                    ParamSpec::new(name, Dim::Length, "cutoff: E ≡ 0 for r ≥ cutoff").positive()
                } else {
                    spec
                }
            })
            .collect();
        if kind == Kind::External {
            specs.push(ParamSpec::new("t", Dim::Time, "the time, set by the engine at every step").default(0.0));
        }
        let n = specs.len();
        let resolve = |name: &str| {
            vars.iter()
                .position(|(v, _)| *v == name)
                .map(|k| if kind == Kind::External && name == "t" { Slot::Param(n - 1) } else { Slot::Var(k) })
                .or_else(|| names.iter().position(|p| *p == name).map(Slot::Param))
        };
        let d = |e: &Expr, v: &str| e.derivative(v);
        let outputs: Vec<Vec<Expr>> = match kind {
            Kind::Bond | Kind::Pair => {
                let de = d(&energy, "r");
                let d2e = d(&de, "r");
                vec![vec![de.clone()], vec![energy.clone(), de, d2e]]
            }
            Kind::Angle => vec![vec![energy.clone(), d(&energy, "theta")]],
            Kind::External => vec![vec![energy.clone(), d(&energy, "x"), d(&energy, "y"), d(&energy, "z")]],
            _ => {
                let (ev, ea) = (d(&energy, "V"), d(&energy, "A"));
                let (evv, eaa) = (d(&ev, "V"), d(&ea, "A"));
                vec![vec![energy.clone(), ev, ea], vec![evv, eaa]]
            }
        };
        let mut tapes = Vec::new();
        let mut starts = Vec::new();
        for out in &outputs {
            starts.push((n + tapes.len()) as f64);
            let refs: Vec<&Expr> = out.iter().collect();
            tapes.extend(compile(&refs, &resolve).map_err(CustomError::Expression)?);
        }
        tapes.extend(starts);
        let specs: &'static [ParamSpec] = Box::leak(specs.into_boxed_slice());
        Ok(Box::leak(Box::new(CustomLaw { kind, text: text.to_string(), energy, specs, tapes })))
    }

    /// The parameter vector of a term: `values` (in declaration order; for an
    /// external, without the time slot) followed by the tapes.
    pub fn params(&self, values: &[f64]) -> Vec<f64> {
        let mut p = values.to_vec();
        if self.kind == Kind::External {
            p.push(0.0);
        }
        p.extend_from_slice(&self.tapes);
        p
    }

    /// The energy expression as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The energy's tree (for translations to other engines).
    pub fn energy(&self) -> &Expr {
        &self.energy
    }

    /// The index of the time slot of an external's parameters.
    pub fn time_slot(&self) -> Option<usize> {
        (self.kind == Kind::External && self.energy.depends_on("t")).then(|| self.specs.len() - 1)
    }
}

impl Entry for CustomLaw {
    fn name(&self) -> &'static str {
        "custom"
    }
    fn category(&self) -> &'static str {
        self.kind.keyword()
    }
    fn summary(&self) -> &'static str {
        Custom.summary()
    }
    fn doc(&self) -> &'static str {
        Custom.doc()
    }
    fn params(&self) -> &'static [ParamSpec] {
        self.specs
    }
}

impl Interaction for CustomLaw {
    fn kind(&self) -> Kind {
        self.kind
    }
    fn expression(&self) -> Option<&Expr> {
        Some(&self.energy)
    }
    /// Bonds, angles and pairs: LAMMPS' lepton styles with the expression,
    /// parameters written as numbers; r0 = 0 and θ0 = 0 make Lepton's
    /// displacement variables the distance and the angle (θ in radians).
    /// Externals: `fix addforce` with atom-style variables of −∇E and E.
    fn lammps(&self, term: &LammpsTerm) -> Translation {
        if self.kind == Kind::External {
            return Some(Ok(LammpsStyle::ExpressionVariables));
        }
        if !matches!(self.kind, Kind::Bond | Kind::Angle | Kind::Pair) {
            return None;
        }
        let value = |n: &str| self.specs.iter().position(|p| p.name == n).map(|k| term.params[k]);
        let expression = match lepton::lepton(&self.energy, &value) {
            Ok(expression) => expression,
            Err(e) => return Some(Err(format!("{} `{}`: {e}", self.kind.with_article(), term.label))),
        };
        match self.kind {
            Kind::Bond => lepton_bond(expression, 0.0),
            Kind::Angle => bonded("lepton", format!("0.0 \"{expression}\"")),
            _ => pair("lepton", format!("\"{expression}\" {}", num(term.params[0]))),
        }
    }
    fn law(&self) -> Law {
        match self.kind {
            Kind::Bond => Law::Radial { eval: radial_eval, force: radial_force, range: |_| f64::INFINITY },
            Kind::Pair => Law::Radial { eval: pair_eval, force: pair_force, range: |p| p[0] },
            Kind::Angle => Law::ThreeBody(angle_eval),
            Kind::External => Law::OneBody(external_eval),
            Kind::Body | Kind::Contact | Kind::Tetra => Law::Surface { eval: body_eval, hessian: body_hessian, gpu: SurfaceGpu::None },
        }
    }
}

static PARAMS: [ParamSpec; 0] = [];

interaction!(
    Custom,
    "custom",
    Kind::Body,
    "Any bond, angle, pair, external or body law given as an energy expression, with exact derivatives (see `cellmd list custom`)",
    Law::Surface { eval: body_eval, hessian: body_hessian, gpu: SurfaceGpu::None }
);

/// The shared checks on a set of expressions of every kind, and equality
/// with the built-in law each one restates (to 1e-14).
#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::interactions::testing::*;
    use crate::interactions::{cosine_angle, harmonic, harmonic_angle, soft, surface_tension, turgor, KindLaw, RadialLaw};

    fn law(kind: Kind, text: &str, params: &[(&str, f64)]) -> (&'static CustomLaw, Vec<f64>) {
        let declared: Vec<Declared> = params.iter().map(|(n, _)| Declared { name: n.to_string(), dim: Dim::Dimensionless }).collect();
        let values: Vec<f64> = params.iter().map(|(_, v)| *v).collect();
        let law = CustomLaw::new(kind, text, &declared).unwrap_or_else(|e| panic!("{text}: {e:?}"));
        (law, law.params(&values))
    }

    fn pair_at(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(0.2, -0.1, 0.3);
        [a, a + DVec3::new(2.0, -2.0, 1.0) / 3.0 * r]
    }

    fn angle_at(deg: f64) -> [DVec3; 3] {
        let j = DVec3::new(-0.3, 0.1, 0.6);
        let t = deg.to_radians();
        [j + 0.25 * DVec3::new(0.0, 1.0, 0.2), j, j + 0.4 * DVec3::new(0.3, t.cos(), t.sin())]
    }

    /// F = −∇E, Σf = 0, Σr×f = 0, rigid-motion invariance, E″ against
    /// differences of E′ and the force-only path against `eval`, for radial laws
    /// of several shapes (piecewise ones included, away from their kinks).
    /// A custom law's kind, energy expression and parameters.
    type Case<'a> = (Kind, &'a str, &'a [(&'a str, f64)]);

    #[test]
    fn shared_checks_on_radial_expressions() {
        let cases: [Case; 6] = [
            (Kind::Bond, "0.5*k*(r-r0)^2", &[("k", 40.0), ("r0", 0.3)]),
            (Kind::Bond, "-0.5*k*R^2*ln(1-(r/R)^2)", &[("k", 30.0), ("R", 1.5)]),
            (Kind::Bond, "k*(r>r0)*(r-r0)^3 + e*exp(-r)", &[("k", 5.0), ("r0", 0.5), ("e", 0.1)]),
            (Kind::Pair, "A*(1+cos(pi*r/rc))", &[("cutoff", 1.5), ("A", 1.0), ("rc", 1.5)]),
            (Kind::Pair, "4*eps*((s/r)^12-(s/r)^6) - c", &[("cutoff", 1.2), ("eps", 1.0), ("s", 0.5), ("c", 0.01)]),
            (Kind::Pair, "k*max(0, d-r)^2 + abs(r-1)", &[("cutoff", 2.0), ("k", 3.0), ("d", 0.8)]),
        ];
        for (kind, text, params) in cases {
            let (law, p) = law(kind, text, params);
            for r in [0.42, 0.7, 1.1] {
                assert_all_checks(law, &p, &pair_at(r), 1e-6, 1e-3);
            }
        }
    }

    #[test]
    fn shared_checks_on_angle_and_external_expressions() {
        let (bend, p) = law(Kind::Angle, "kappa*(1-cos(theta-theta0)) + c*(theta-1)^4", &[("kappa", 2.0), ("theta0", 2.0), ("c", 0.3)]);
        for deg in [20.0, 75.0, 120.0, 170.0] {
            assert_all_checks(bend, &p, &angle_at(deg), 1e-6, 1e-3);
        }
        let (straight, p) = law(Kind::Angle, "kappa*(1-cos(theta-theta0))", &[("kappa", 2.0), ("theta0", std::f64::consts::PI)]);
        assert_zero_force_at_rest(straight, &p, &[DVec3::ZERO, DVec3::X, 2.0 * DVec3::X], 2.0);
        let (field, p) = law(Kind::External, "-f*x + k*(y^2 + z^2)*exp(-z)", &[("f", 1.5), ("k", 0.7)]);
        for x in [DVec3::ZERO, DVec3::new(1.0, -0.5, 0.3)] {
            assert_all_checks(field, &p, &[x], 1e-6, 1e-3);
        }
    }

    #[test]
    fn shared_checks_on_body_expressions() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1]) {
            let (v, a) = (mesh.volume(&x), mesh.area(&x));
            let (body, p) =
                law(Kind::Body, "0.5*K*(V-V0)^2/V0 + gamma*A + c*A^2/V", &[("K", 1000.0), ("V0", 1.1 * v), ("gamma", 5.0), ("c", 0.2)]);
            assert_surface_checks(body, &p, &mesh, &x, 1e-6, 1e-3);
            let (rest, p) = law(Kind::Body, "0.5*K*(V-V0)^2 + 0.5*G*(A-A0)^2", &[("K", 100.0), ("V0", v), ("G", 7.0), ("A0", a)]);
            assert_surface_zero_force_at_rest(rest, &p, &mesh, &x, 100.0);
        }
    }

    fn close(a: f64, b: f64, what: &str) {
        assert!((a - b).abs() <= 1e-14 * a.abs().max(b.abs()).max(1e-300), "{what}: custom {a} vs built-in {b}");
    }

    fn close3(a: DVec3, b: DVec3, scale: f64, what: &str) {
        assert!((a - b).length() <= 1e-14 * scale, "{what}: custom {a} vs built-in {b}");
    }

    /// The built-in laws restated as expressions give the same energies, forces
    /// and E″ to 1e-14 (relative to the largest force of the configuration).
    #[test]
    fn expressions_of_built_in_laws_equal_the_built_ins() {
        let radial = [
            (
                law(Kind::Bond, "0.5*k*(r-r0)^2", &[("k", 400.0), ("r0", 0.1)]),
                params_of(&harmonic::Harmonic, &[("k", 400.0), ("r0", 0.1)]),
                harmonic::Harmonic.law(),
            ),
            (
                law(Kind::Pair, "A*(1+cos(pi*r/rc))", &[("cutoff", 1.5), ("A", 10.0), ("rc", 1.5)]),
                params_of(&soft::Soft, &[("A", 10.0), ("rc", 1.5)]),
                soft::Soft.law(),
            ),
        ];
        for ((custom, cp), bp, builtin) in radial {
            let RadialLaw { eval: ce, force: cf, range: cr } = RadialLaw::from_law(custom.law()).unwrap();
            let RadialLaw { eval: be, force: bf, range: br } = RadialLaw::from_law(builtin).unwrap();
            assert_eq!(cr(&cp), br(&bp));
            for r in [0.05, 0.1, 0.37, 0.9, 1.49, 1.5, 2.0] {
                let (c, b) = (ce(&cp, r), be(&bp, r));
                let what = format!("{} at r = {r}", custom.text());
                close(c.energy, b.energy, &what);
                close(c.de_dr, b.de_dr, &what);
                close(c.d2e_dr2, b.d2e_dr2, &what);
                close(cf(&cp, r * r), bf(&bp, r * r), &what);
            }
        }
        let angles = [
            (
                law(Kind::Angle, "K*(1+cos(theta))", &[("K", 0.7)]),
                params_of(&cosine_angle::CosineAngle, &[("K", 0.7)]),
                cosine_angle::CosineAngle.law(),
            ),
            (
                law(Kind::Angle, "0.5*k*(theta-theta0)^2", &[("k", 3.0), ("theta0", 110f64.to_radians())]),
                params_of(&harmonic_angle::HarmonicAngle, &[("k", 3.0), ("theta0", 110.0)]),
                harmonic_angle::HarmonicAngle.law(),
            ),
        ];
        for ((custom, cp), bp, builtin) in angles {
            for deg in [10.0, 70.0, 110.0, 150.0, 179.0] {
                let x = angle_at(deg);
                let (c, b) = (evaluate(custom.law(), &cp, &x), evaluate(builtin, &bp, &x));
                let what = format!("{} at {deg}°", custom.text());
                close(c.0, b.0, &what);
                let scale = b.1.iter().map(|f| f.length()).fold(0.0, f64::max);
                for (fc, fb) in c.1.iter().zip(&b.1) {
                    close3(*fc, *fb, scale, &what);
                }
            }
        }
        for (_, mesh, x) in deformed_icospheres(&[1]) {
            let v = mesh.volume(&x);
            let bodies = [
                (
                    law(Kind::Body, "-dp0*(V-v0) + 0.5*k*(V-v0)^2/v0", &[("dp0", 40.0), ("k", 700.0), ("v0", 1.2 * v)]),
                    params_of(&turgor::Turgor, &[("k", 700.0), ("dp0", 40.0), ("v0", 1.2 * v)]),
                    turgor::Turgor.law(),
                ),
                (
                    law(Kind::Body, "gamma*A", &[("gamma", 665.0)]),
                    params_of(&surface_tension::SurfaceTension, &[("gamma", 665.0)]),
                    surface_tension::SurfaceTension.law(),
                ),
            ];
            for ((custom, cp), bp, builtin) in bodies {
                let (c, b) = (evaluate_surface(custom.law(), &cp, &mesh, &x), evaluate_surface(builtin, &bp, &mesh, &x));
                close(c.0, b.0, custom.text());
                let scale = b.1.iter().map(|f| f.length()).fold(0.0, f64::max);
                for (fc, fb) in c.1.iter().zip(&b.1) {
                    close3(*fc, *fb, scale, custom.text());
                }
            }
        }
    }

    /// The body term's second-order model is exact where it claims to be:
    /// for E = ½K(V − V0)² at V = V0 (no E_V) plus γA, against second
    /// differences of the energy.
    #[test]
    fn body_stiffness_is_the_gauss_newton_model() {
        let (mesh, x) = deformed_icosphere(1, 1.5, 0.05);
        let v = mesh.volume(&x);
        let (body, p) = law(Kind::Body, "0.5*K*(V-V0)^2/V0 + gamma*A", &[("K", 1000.0), ("V0", v), ("gamma", 30.0)]);
        assert_surface_hessian(body, &p, &mesh, &x, |_| 0.0, 1e-4, 1e-5);
    }

    #[test]
    fn errors_name_the_symbol_or_the_parameter() {
        let declared = |names: &[&str]| names.iter().map(|n| Declared { name: n.to_string(), dim: Dim::Dimensionless }).collect::<Vec<_>>();
        let expression = |kind, text, names: &[&str]| match CustomLaw::new(kind, text, &declared(names)) {
            Err(CustomError::Expression(e)) => format!("{}..{}: {}", e.span.start, e.span.end, e.message),
            Err(CustomError::Parameter { index, message }) => format!("parameter {index}: {message}"),
            Ok(_) => "accepted".into(),
        };
        assert_eq!(
            expression(Kind::Bond, "k*(r-q)^2", &["k"]),
            "5..6: found unknown symbol `q`, expected a variable of a bond or a declared parameter: r, k"
        );
        assert_eq!(
            expression(Kind::Angle, "k*r", &["k"]),
            "2..3: found unknown symbol `r`, expected a variable of an angle or a declared parameter: theta, k"
        );
        assert!(expression(Kind::Bond, "k*foo(r)", &["k"]).starts_with("2..5: found unknown function `foo`"));
        assert!(expression(Kind::Bond, "k*(r-", &["k"]).starts_with("5..5: found the end of the expression"));
        assert_eq!(
            expression(Kind::Bond, "k*r", &["k", "unused"]),
            "parameter 1: parameter `unused` is not used in the expression; expected every declared parameter in it"
        );
        assert!(expression(Kind::Bond, "k*r", &["k", "r"]).starts_with("parameter 1: `r` is a variable of a bond expression"));
        assert!(expression(Kind::Body, "k*V", &["k", "k"]).starts_with("parameter 1: parameter `k` is declared twice"));
        assert!(expression(Kind::Contact, "d", &[]).contains("expected one of the kinds bond"));
        assert!(expression(Kind::Bond, "thermo(pe)*r", &[]).starts_with("0..10: found unknown symbol `thermo(pe)`"));
        assert_eq!(expression(Kind::Pair, "A*r", &["cutoff", "A"]), "accepted", "a pair's cutoff may be left out of E");
    }

    /// `coeff` edits the parameter values in front of the tapes: the law reads them.
    #[test]
    fn parameters_are_read_from_the_vector() {
        let (spring, mut p) = law(Kind::Bond, "0.5*k*(r-r0)^2", &[("k", 2.0), ("r0", 1.0)]);
        let eval = RadialLaw::from_law(spring.law()).unwrap().eval;
        assert_eq!(eval(&p, 3.0).energy, 4.0);
        p[param_index_of(spring, "r0")] = 2.0;
        assert_eq!(eval(&p, 3.0).energy, 1.0);
    }

    fn param_index_of(law: &CustomLaw, name: &str) -> usize {
        crate::interactions::param_index(law, name).unwrap()
    }
}
