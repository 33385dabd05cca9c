//! WGSL evaluators generated for a model's `custom` terms.
//!
//! Each custom bond, angle, pair or external term k gets its own function,
//! `custom_k_radial`, `custom_k_three` or `custom_k_one`, written from its
//! energy tree and the tree's symbolic derivatives by [`crate::expr::wgsl`]
//! (parameters read from the term's slots `p[i]`, in f32 like every GPU
//! law), and its own dispatch index past the registry's
//! ([`gpu_kinds`]). The composed program (`shader::compose_with`)
//! holds them beside the registered evaluators; naga validates it.
//!
//! An external with expression parameters (`field fx "-k*x"`, a wall
//! whose `d` is a formula of `t`; a custom external that reads `t` has one
//! too, its time slot) gets its own dispatch index past the custom terms'
//! and a function `external_m_one` that evaluates each expression at the
//! particle's unwrapped position `x` and the step's time `t` (`sim_time()`,
//! shaders/common/integrate.wgsl), puts the values in the parameter slots
//! and calls the law's evaluator, as `External::at` does on the CPU.

use std::fmt::Write;

use crate::expr::wgsl::wgsl;
use crate::forcefield::{TermType, Typed};
use crate::interactions::{Kind, REGISTRY};
use crate::system::{registry_index, Model};

/// Whether a term is a custom expression.
fn is_custom(term: &TermType) -> bool {
    term.interaction.expression().is_some()
}

/// The terms the GPU packs, in its order: bond types, angle types, pair
/// rules, externals.
fn terms(model: &Model) -> impl Iterator<Item = &TermType> {
    let (bonds, angles, pairs) = (model.bond_types.iter(), model.angle_types.iter(), model.pair_rules.iter());
    bonds.map(Typed::term).chain(angles.map(Typed::term)).chain(pairs.map(Typed::term)).chain(model.externals.iter().map(|e| e.term.term()))
}

/// The dispatch index of every packed term: its registry index, for the
/// k-th custom term `REGISTRY.len() + k`, and for the m-th external with
/// expression parameters `REGISTRY.len() + customs + m`.
pub fn gpu_kinds(model: &Model) -> Vec<u32> {
    let mut kinds = law_kinds(model);
    let mut next = (REGISTRY.len() + terms(model).filter(|t| is_custom(t)).count()) as u32;
    let first_external = kinds.len() - model.externals.len();
    for (kind, external) in kinds[first_external..].iter_mut().zip(&model.externals) {
        if !external.expressions.is_empty() {
            *kind = next;
            next += 1;
        }
    }
    kinds
}

/// The dispatch index of every packed term's law: its registry index, or
/// for the k-th custom term `REGISTRY.len() + k`.
fn law_kinds(model: &Model) -> Vec<u32> {
    let mut custom = 0;
    terms(model)
        .map(|t| {
            if is_custom(t) {
                custom += 1;
                (REGISTRY.len() + custom - 1) as u32
            } else {
                registry_index(t) as u32
            }
        })
        .collect()
}

/// The parameters a term sends to the GPU: a custom term's values without its tapes.
pub fn gpu_params(term: &TermType) -> &[f64] {
    if is_custom(term) {
        &term.params[..term.interaction.params().len()]
    } else {
        &term.params
    }
}

/// Generated evaluators and their dispatch cases (radial, three-body, one-body).
#[derive(Default)]
pub struct CustomSource {
    pub functions: String,
    pub radial_cases: String,
    pub three_cases: String,
    pub one_cases: String,
    /// `mover_velocity` cases of moving groups with velocity fields (src/gpu/protocol.rs).
    pub mover_cases: String,
    /// Whether the model has body surface terms: the WGSL constant
    /// `BODY_TERMS`, so that a model without them compiles its implicit
    /// step's products without their gathers and their barrier.
    pub body_terms: bool,
    /// Whether the model has contact terms between bodies: the WGSL constant
    /// `CONTACT_TERMS`, likewise for the implicit step's contact rows and clamp.
    pub contact_terms: bool,
}

/// The WGSL of every custom term of `model`.
pub fn source(model: &Model) -> Result<CustomSource, String> {
    let mut out = CustomSource { body_terms: model.has_surface_terms(), contact_terms: model.has_contact_terms(), ..Default::default() };
    for (k, term) in terms(model).filter(|t| is_custom(t)).enumerate() {
        let index = REGISTRY.len() + k;
        let energy = term.interaction.expression().expect("a custom term has its expression");
        let specs = term.interaction.params();
        let kind = term.interaction.kind();
        let name = |n: &str| match n {
            "r" | "x" | "y" | "z" if matches!((kind, n), (Kind::Bond | Kind::Pair, "r") | (Kind::External, "x" | "y" | "z")) => {
                Some(if kind == Kind::External { format!("x.{n}") } else { n.to_string() })
            }
            "theta" if kind == Kind::Angle => Some("theta".into()),
            _ => specs.iter().position(|s| s.name == n).map(|i| format!("p[{i}]")),
        };
        let label = &term.label.text;
        let code =
            |e: &crate::expr::Expr| wgsl(e, &name).map_err(|e| format!("{} `{label}` on the GPU: {}", kind.with_article(), e.message));
        match kind {
            Kind::Bond | Kind::Pair => {
                let (e, de) = (code(energy)?, code(&energy.derivative("r"))?);
                let cut = if kind == Kind::Pair { "    if r >= p[0] { return RADIAL_ZERO; }\n" } else { "" };
                writeln!(
                    out.functions,
                    "fn custom_{k}_radial(p: array<f32, 8>, r: f32) -> Radial {{\n{cut}    return Radial({e}, {de});\n}}"
                )
                .unwrap();
                writeln!(out.radial_cases, "        case {index}u: {{ return custom_{k}_radial(p, r); }}").unwrap();
            }
            Kind::Angle => {
                let (e, de) = (code(energy)?, code(&energy.derivative("theta"))?);
                writeln!(
                    out.functions,
                    "fn custom_{k}_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {{\n    \
                     let a = angle_arms(ri, rj, rk);\n    let c = clamp(a.c, -1.0, 1.0);\n    let theta = acos(c);\n    \
                     let s = sqrt(max(1.0 - c * c, 0.0));\n    let de_dc = select(-({de}) / s, 0.0, s == 0.0);\n    \
                     let fi = -de_dc * (a.vh - c * a.uh) / a.lu;\n    let fk = -de_dc * (a.uh - c * a.vh) / a.lv;\n    \
                     return ThreeBody({e}, fi, -fi - fk, fk);\n}}"
                )
                .unwrap();
                writeln!(out.three_cases, "        case {index}u: {{ return custom_{k}_three(p, ri, rj, rk); }}").unwrap();
            }
            Kind::External => {
                let grad: Vec<String> = ["x", "y", "z"].iter().map(|v| code(&energy.derivative(v))).collect::<Result<_, _>>()?;
                writeln!(
                    out.functions,
                    "fn custom_{k}_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {{\n    return OneBody({}, -vec3<f32>({}, {}, {}));\n}}",
                    code(energy)?,
                    grad[0],
                    grad[1],
                    grad[2]
                )
                .unwrap();
                writeln!(out.one_cases, "        case {index}u: {{ return custom_{k}_one(p, x); }}").unwrap();
            }
            Kind::Body | Kind::Contact | Kind::Tetra => unreachable!("surface, contact and volume terms are not packed"),
        }
    }
    let laws = law_kinds(model);
    let (kinds, first_external) = (gpu_kinds(model), laws.len() - model.externals.len());
    for (e, external) in model.externals.iter().enumerate().filter(|(_, e)| !e.expressions.is_empty()) {
        let (law, index) = (laws[first_external + e] as usize, kinds[first_external + e]);
        let call = match REGISTRY.get(law) {
            Some(interaction) => format!("{}_one(q, x)", interaction.name()),
            None => format!("custom_{}_one(q, x)", law - REGISTRY.len()),
        };
        let name = |n: &str| match n {
            "x" | "y" | "z" => Some(format!("x.{n}")),
            "t" => Some("t".to_string()),
            _ => None,
        };
        let label = &external.term.term().label.text;
        let mut body = String::new();
        for (k, expr) in &external.expressions {
            let code = wgsl(expr, &name).map_err(|e| format!("the external `{label}` on the GPU: {}", e.message))?;
            writeln!(body, "    q[{k}] = {code};").unwrap();
        }
        writeln!(
            out.functions,
            "fn external_{index}_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {{\n    let t = sim_time();\n    var q = p;\n{body}    return {call};\n}}"
        )
        .unwrap();
        writeln!(out.one_cases, "        case {index}u: {{ return external_{index}_one(p, x); }}").unwrap();
    }
    Ok(out)
}
