//! Composes the WGSL program from `shaders/` at start time.
//!
//! The program is the common layout and helpers, the Philox generator, every
//! interaction type's evaluator file (`shaders/interactions/NAME.wgsl`, which
//! defines `NAME_radial`, `NAME_three` or `NAME_one` by its law family), the
//! generated dispatch functions `radial_law`, `three_body_law` and
//! `one_body_law` (a `switch` on the registry index), and the kernels
//! (neighbour list, forces, integrator). One module holds every entry point.
//! Surface laws define `NAME_face` or `NAME_node` by their [`SurfaceGpu`]
//! form, dispatched by `surface_law` and `node_law` from the surface
//! kernels (src/gpu/surface.rs). Volume-element laws define `NAME_tetra`
//! (W and P at F), dispatched by `tetra_law` from the element kernel
//! (src/gpu/tetra.rs).
//!
//! Node–face contact laws ([`Law::Contact`]) define `NAME_contact(p, d)`,
//! b(d) as a `Radial` of the node–face distance, dispatched by
//! `contact_law` from the contact kernel (src/gpu/contact.rs).
//! Area-weighted contact laws ([`Law::ContactArea`]: adhesion) define
//! `NAME_switch(p, d)` (s and s′ as a `Radial`) and `NAME_density(p)` (ε),
//! dispatched by `contact_area_switch` and `contact_area_density` from the
//! adhesion kernels (src/gpu/adhesion.rs).
//!
//! Only laws with a GPU kernel take part ([`Law::runs_on_gpu`]). Custom
//! body terms have none yet: they have no evaluator file, no
//! dispatch case, and the GPU backend refuses decks that use them, so such a
//! deck never runs on the GPU without those forces. A WGSL file for a law without the kernel to call it is refused
//! by a test, so a shader cannot pretend to cover one.
//!
//! Parameter names: an evaluator receives its parameters as `p: array<f32,
//! 8>` in schema order (`PARAMS` of the interaction's `.rs`) and reads them
//! by name, never by bare number. Before each evaluator file the program
//! declares one constant per schema entry, `NAME_PARAM` in upper case with
//! its schema index ([`param_constants`]: `const HARMONIC_K: u32 = 0u;`,
//! `const HARMONIC_R0: u32 = 1u;`), so `harmonic.wgsl` writes `p[HARMONIC_K]`.
//! A test refuses any `p[<digit>` in `shaders/interactions/` and in the
//! kinetic rules' files. (A new evaluator, e.g. a volume element's, follows
//! the same rule.)
//!
//! Kinetic rules decided on the device (src/gpu/kinetics.rs) are
//! dispatched the same way: each rule with a [`GpuForm`] has its evaluator
//! beside it (`src/kinetics/NAME.wgsl`, defining `NAME_rate`,
//! `NAME_beyond` or `NAME_on_rate`), preceded by its parameter names
//! (`const CATCH_SLIP_KC0: u32 = 0u;`); the generated `rule_form`,
//! `unbind_law`, `threshold_law` and `rebind_law` switch on the rule's code,
//! its registry index + 1 ([`rule_code`]), which the host writes into the
//! kinetics buffer. No list of rule names exists outside [`RULES`].
//!
//! The program starts with its prelude: every constant the host and the
//! kernels share, generated from its Rust definition (src/gpu/prelude.rs).
//! Geometry both sides compute (the closest point of a triangle) has its WGSL
//! twin beside the Rust, in `src/mesh.wgsl`.

use std::fmt::Write;

use super::custom::CustomSource;
use super::prelude::TABLES;
use crate::interactions::{Entry, Law, SurfaceGpu, REGISTRY};
use crate::kinetics::{rule_index, GpuForm, KineticRule, RULES};

mod embedded {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

pub use embedded::{COMMON_SHADERS, INTERACTION_SHADERS, KINETIC_SHADERS};

/// The WGSL twins of the mesh geometry the kernels need, beside src/mesh.rs.
const MESH_SHADER: &str = include_str!("../mesh.wgsl");

/// The common files in the order they must appear (declarations first).
const COMMON_ORDER: [&str; 19] = [
    "layout",
    "philox",
    "neighbor",
    "forces",
    "surface",
    "integrate",
    "contact",
    "kinetics",
    "bind",
    "tetra",
    "special",
    "adhesion",
    "protocol",
    "implicit",
    "implicit_contact",
    "implicit_split",
    "implicit_constraints",
    "shake",
    "fire",
];

fn common(name: &str) -> &'static str {
    COMMON_SHADERS.iter().find(|(stem, _)| *stem == name).map(|(_, src)| *src).unwrap_or_else(|| panic!("shaders/common/{name}.wgsl"))
}

/// The evaluator file of a registered interaction type.
pub fn interaction_source(name: &str) -> Option<&'static str> {
    INTERACTION_SHADERS.iter().find(|(stem, _)| *stem == name).map(|(_, src)| *src)
}

/// The evaluator file of a registered kinetic rule (src/kinetics/NAME.wgsl).
pub fn kinetic_source(name: &str) -> Option<&'static str> {
    KINETIC_SHADERS.iter().find(|(stem, _)| *stem == name).map(|(_, src)| *src)
}

/// The code of a kinetic rule in the kinetics buffer and the generated
/// dispatch: its registry index + 1 (0: no rule); None for a rule the device
/// does not decide.
pub fn rule_code(rule: &dyn KineticRule) -> Option<u32> {
    rule.effect().gpu_form().map(|_| rule_index(rule) as u32 + 1)
}

/// The prelude: one declaration per shared constant.
fn prelude() -> String {
    let mut out = String::from("// Generated from the Rust definitions (src/gpu/prelude.rs).\n");
    TABLES.iter().flat_map(|t| t.iter()).for_each(|c| out.push_str(&c.declaration()));
    out
}

/// The device forms' codes and the dispatch of the kinetic rules by code
/// (see the module doc).
fn kinetic_dispatch() -> String {
    let form_name = |form: GpuForm| format!("FORM_{}", form.suffix().to_uppercase());
    let out: String = GpuForm::ALL.iter().map(|&f| format!("const {}: u32 = {}u;\n", form_name(f), f as u32)).collect();
    let mut form = String::from("fn rule_form(code: u32) -> u32 {\n    switch code {\n");
    let mut unbind = String::from("fn unbind_law(code: u32, p: array<f32, 8>, f: f32, kt: f32) -> f32 {\n    switch code {\n");
    let mut threshold =
        String::from("fn threshold_law(code: u32, p: array<f32, 8>, force: f32, strain: f32, u: f32) -> Beyond {\n    switch code {\n");
    let mut rebind = String::from("fn rebind_law(code: u32, p: array<f32, 8>) -> vec2<f32> {\n    switch code {\n");
    for rule in RULES.iter().copied() {
        let (Some(gpu), Some(code)) = (rule.effect().gpu_form(), rule_code(rule)) else { continue };
        let name = rule.name();
        writeln!(form, "        case {code}u: {{ return {}; }}", form_name(gpu)).unwrap();
        let (table, call) = match gpu {
            GpuForm::Unbind => (&mut unbind, format!("{name}_rate(p, f, kt)")),
            GpuForm::Threshold => (&mut threshold, format!("{name}_beyond(p, force, strain, u)")),
            GpuForm::Rebind => (&mut rebind, format!("{name}_on_rate(p)")),
        };
        writeln!(table, "        case {code}u: {{ return {call}; }}").unwrap();
    }
    form.push_str("        default: { return 0u; }\n    }\n}\n");
    unbind.push_str("        default: { return 0.0; }\n    }\n}\n");
    threshold.push_str("        default: { return Beyond(false, 0.0); }\n    }\n}\n");
    rebind.push_str("        default: { return vec2<f32>(0.0); }\n    }\n}\n");
    out + &form + &unbind + &threshold + &rebind
}

/// The dispatch functions over the registry (and a model's custom terms).
fn dispatch(custom: &CustomSource) -> String {
    let mut radial = String::from("fn radial_law(kind: u32, p: array<f32, 8>, r: f32) -> Radial {\n    switch kind {\n");
    let mut three = String::from(
        "fn three_body_law(kind: u32, p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {\n    switch kind {\n",
    );
    let mut one = String::from("fn one_body_law(kind: u32, p: array<f32, 8>, x: vec3<f32>) -> OneBody {\n    switch kind {\n");
    let mut surface = String::from(
        "fn surface_law(kind: u32, p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {\n    switch kind {\n",
    );
    let mut node = String::from("fn node_law(kind: u32, p: array<f32, 8>, m: f32, a: f32) -> NodeCurvature {\n    switch kind {\n");
    // Node–face contact laws (src/gpu/contact.rs): b(d) as a Radial of the distance.
    let mut contact = String::from("fn contact_law(kind: u32, p: array<f32, 8>, d: f32) -> Radial {\n    switch kind {\n");
    // Area-weighted contact laws (src/gpu/adhesion.rs): the switch s(d), s′(d) and the density ε.
    let mut area_switch = String::from("fn contact_area_switch(kind: u32, p: array<f32, 8>, d: f32) -> Radial {\n    switch kind {\n");
    let mut area_density = String::from("fn contact_area_density(kind: u32, p: array<f32, 8>) -> f32 {\n    switch kind {\n");
    let mut tetra = String::from(
        "fn tetra_law(kind: u32, p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> TetraDensity {\n    switch kind {\n",
    );
    for (index, interaction) in REGISTRY.iter().enumerate() {
        let name = interaction.name();
        let (out, call) = match interaction.law() {
            Law::Radial { .. } => (&mut radial, format!("{name}_radial(p, r)")),
            Law::ThreeBody(_) => (&mut three, format!("{name}_three(p, ri, rj, rk)")),
            Law::OneBody(_) => (&mut one, format!("{name}_one(p, x)")),
            Law::Surface { gpu: SurfaceGpu::PerFace, .. } => (&mut surface, format!("{name}_face(p, body, g)")),
            Law::Surface { gpu: SurfaceGpu::NodeCurvature, .. } => (&mut node, format!("{name}_node(p, m, a)")),
            Law::Contact { .. } => (&mut contact, format!("{name}_contact(p, d)")),
            Law::Tetra(_) => (&mut tetra, format!("{name}_tetra(p, f, j, f_inv_t)")),
            Law::ContactArea { .. } => {
                writeln!(area_switch, "        case {index}u: {{ return {name}_switch(p, d); }}").unwrap();
                (&mut area_density, format!("{name}_density(p)"))
            }
            Law::Surface { .. } | Law::NodalTetra { .. } => continue,
        };
        writeln!(out, "        case {index}u: {{ return {call}; }}").unwrap();
    }
    radial.push_str(&custom.radial_cases);
    three.push_str(&custom.three_cases);
    one.push_str(&custom.one_cases);
    radial.push_str("        default: { return RADIAL_ZERO; }\n    }\n}\n");
    three.push_str("        default: { return ThreeBody(0.0, vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0)); }\n    }\n}\n");
    one.push_str("        default: { return OneBody(0.0, vec3<f32>(0.0)); }\n    }\n}\n");
    surface.push_str("        default: { return SurfaceFace(0.0, vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0)); }\n    }\n}\n");
    node.push_str("        default: { return NodeCurvature(0.0, 0.0, 0.0); }\n    }\n}\n");
    contact.push_str("        default: { return RADIAL_ZERO; }\n    }\n}\n");
    tetra.push_str("        default: { return TetraDensity(0.0, mat3x3<f32>()); }\n    }\n}\n");
    area_switch.push_str("        default: { return RADIAL_ZERO; }\n    }\n}\n");
    area_density.push_str("        default: { return 0.0; }\n    }\n}\n");
    // Velocity fields of moving groups (src/gpu/protocol.rs).
    let movers = format!(
        "fn mover_velocity(m: u32, x: vec3<f32>, t: f32) -> vec3<f32> {{\n    switch m {{\n{}        default: {{ return vec3<f32>(0.0); }}\n    }}\n}}\n",
        custom.mover_cases
    );
    radial + &three + &one + &surface + &node + &contact + &tetra + &area_switch + &area_density + &movers
}

/// The whole program for models without custom terms.
pub fn compose() -> String {
    compose_with(&CustomSource::default())
}

/// The WGSL constants naming an interaction's (or a kinetic rule's)
/// parameters: `const NAME_PARAM: u32 = INDEX;` for each entry of its schema
/// (see the module doc).
pub fn param_constants(entry: &dyn Entry) -> String {
    let prefix = entry.name().to_uppercase();
    let lines = entry.params().iter().enumerate().map(|(k, p)| format!("const {prefix}_{}: u32 = {k}u;\n", p.name.to_uppercase()));
    lines.collect()
}

/// The whole program, with a model's generated custom evaluators.
pub fn compose_with(custom: &CustomSource) -> String {
    let mut program = prelude();
    for name in &COMMON_ORDER[..2] {
        program.push_str(common(name));
    }
    program.push_str(MESH_SHADER);
    for interaction in REGISTRY.iter().filter(|i| i.law().runs_on_gpu()) {
        let source = interaction_source(interaction.name())
            .unwrap_or_else(|| panic!("interaction `{}` has no shaders/interactions/{0}.wgsl", interaction.name()));
        program.push_str(&param_constants(*interaction));
        program.push_str(source);
    }
    for rule in RULES.iter().filter(|r| r.effect().gpu_form().is_some()) {
        let source = kinetic_source(rule.name()).unwrap_or_else(|| panic!("kinetic rule `{}` has no src/kinetics/{0}.wgsl", rule.name()));
        program.push_str(&param_constants(*rule));
        program.push_str(source);
    }
    program.push_str(&kinetic_dispatch());
    program.push_str(&custom.functions);
    writeln!(program, "const BODY_TERMS: bool = {};", custom.body_terms).unwrap();
    writeln!(program, "const CONTACT_TERMS: bool = {};", custom.contact_terms).unwrap();
    program.push_str(&dispatch(custom));
    // The stiffness laws of the implicit step (src/gpu/implicit.rs).
    program.push_str(&super::implicit::stiffness_dispatch());
    for name in &COMMON_ORDER[2..] {
        program.push_str(common(name));
    }
    program
}

/// Parses and validates the composed program with naga (no GPU needed).
pub fn validate(program: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(program).map_err(|e| e.emit_to_string(program))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .map_err(|e| e.emit_to_string(program))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One evaluator file per interaction type whose law runs on the GPU,
    /// and none for the others (refused by the GPU backend); every surface
    /// law with a GPU form is dispatched by `surface_law` or `node_law`.
    #[test]
    fn every_gpu_interaction_has_exactly_one_shader_file_and_no_other_has_one() {
        for interaction in REGISTRY {
            let file = interaction_source(interaction.name()).is_some();
            if interaction.law().runs_on_gpu() {
                assert!(file, "{} has no WGSL evaluator", interaction.name());
            } else {
                assert!(
                    !file,
                    "shaders/interactions/{}.wgsl exists, but the GPU backend has no kernel for its law family",
                    interaction.name()
                );
            }
        }
        for (stem, _) in INTERACTION_SHADERS {
            assert!(crate::interactions::lookup(stem).is_some(), "shaders/interactions/{stem}.wgsl names no registered interaction");
        }
        let cpu_only: Vec<&str> = REGISTRY.iter().filter(|i| !i.law().runs_on_gpu()).map(|i| i.name()).collect();
        assert!(cpu_only.iter().all(|n| !compose().contains(&format!("fn {n}_"))), "{cpu_only:?} appear in the composed program");
        let form = |want: SurfaceGpu| -> Vec<&str> {
            REGISTRY.iter().filter(|i| matches!(i.law(), Law::Surface { gpu, .. } if gpu == want)).map(|i| i.name()).collect()
        };
        assert_eq!(form(SurfaceGpu::PerFace), ["turgor", "turgor_log", "surface_tension", "area_conservation", "surface_shear"]);
        assert_eq!(form(SurfaceGpu::NodeCurvature), ["helfrich_bending"]);
        for name in form(SurfaceGpu::PerFace) {
            assert!(compose().contains(&format!("return {name}_face(p, body, g);")), "{name} has no `surface_law` case");
        }
        for name in form(SurfaceGpu::NodeCurvature) {
            assert!(compose().contains(&format!("return {name}_node(p, m, a);")), "{name} has no `node_law` case");
        }
        let tetra: Vec<&str> = REGISTRY.iter().filter(|i| matches!(i.law(), Law::Tetra(_))).map(|i| i.name()).collect();
        assert_eq!(tetra, ["neo_hookean", "linear_elastic"]);
        for name in tetra {
            assert!(compose().contains(&format!("return {name}_tetra(p, f, j, f_inv_t);")), "{name} has no `tetra_law` case");
        }
        let area: Vec<&str> = REGISTRY.iter().filter(|i| matches!(i.law(), Law::ContactArea { .. })).map(|i| i.name()).collect();
        assert_eq!(area, ["contact_adhesion"]);
        for name in area {
            assert!(compose().contains(&format!("return {name}_switch(p, d);")), "{name} has no `contact_area_switch` case");
            assert!(compose().contains(&format!("return {name}_density(p);")), "{name} has no `contact_area_density` case");
        }
    }

    /// Evaluators read parameters by their generated names: no `p[0]`.
    #[test]
    fn shaders_index_parameters_by_name_only() {
        for (stem, source) in INTERACTION_SHADERS.iter().chain(KINETIC_SHADERS) {
            let bare = source.match_indices("p[").any(|(at, _)| {
                let before = source[..at].chars().next_back();
                let after = source[at + 2..].chars().next();
                !before.is_some_and(|c| c.is_alphanumeric() || c == '_') && after.is_some_and(|c| c.is_ascii_digit())
            });
            assert!(!bare, "shaders/interactions/{stem}.wgsl indexes a parameter by number; use its generated name (NAME_PARAM)");
        }
        assert_eq!(
            param_constants(crate::interactions::lookup("harmonic").unwrap()),
            "const HARMONIC_K: u32 = 0u;\nconst HARMONIC_R0: u32 = 1u;\n"
        );
        assert!(compose().contains("const FENE_SIGMA: u32 = 3u;\n"));
    }

    /// One evaluator file beside each kinetic rule the device decides,
    /// defining the function of its form, and none for the others; each is
    /// dispatched by its code.
    #[test]
    fn every_device_rule_has_exactly_one_shader_file_and_no_other_has_one() {
        let program = compose();
        for rule in RULES {
            let name = rule.name();
            match rule.effect().gpu_form() {
                Some(form) => {
                    let source = kinetic_source(name).unwrap_or_else(|| panic!("{name} has no src/kinetics/{name}.wgsl"));
                    assert!(source.contains(&format!("fn {name}_{}(", form.suffix())), "{name}.wgsl lacks fn {name}_{}", form.suffix());
                    let code = rule_code(*rule).unwrap();
                    assert!(program.contains(&format!("case {code}u: {{ return {name}_{}(", form.suffix())), "{name} is not dispatched");
                }
                None => {
                    assert!(kinetic_source(name).is_none(), "src/kinetics/{name}.wgsl exists, but the device does not decide its effect")
                }
            }
        }
        for (stem, _) in KINETIC_SHADERS {
            assert!(crate::kinetics::lookup_rule(stem).is_some(), "src/kinetics/{stem}.wgsl names no registered rule");
        }
        assert!(program.contains("const CATCH_SLIP_KC0: u32 = 0u;\n"));
    }

    /// Each shared constant is declared once, by the prelude.
    #[test]
    fn prelude_names_are_unique() {
        let mut seen = std::collections::HashSet::new();
        for c in TABLES.iter().flat_map(|t| t.iter()) {
            assert!(seen.insert(c.name), "{} is in two tables", c.name);
        }
    }

    #[test]
    fn composed_program_validates_with_naga() {
        // With and without the code behind `BODY_TERMS` and `CONTACT_TERMS`.
        for (body_terms, contact_terms) in [(false, false), (true, true)] {
            let program = compose_with(&CustomSource { body_terms, contact_terms, ..Default::default() });
            if let Err(e) = validate(&program) {
                panic!("BODY_TERMS {body_terms}, CONTACT_TERMS {contact_terms}: {e}");
            }
        }
    }

    #[test]
    fn a_broken_program_is_rejected() {
        let broken = compose().replace("fn forces(", "fn forces(oops");
        assert!(validate(&broken).is_err());
    }
}
