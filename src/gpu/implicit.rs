//! `integrator implicit` on the device (kernels: shaders/common/implicit.wgsl).
//!
//! # The step
//!
//! As on the CPU (src/integrate/implicit.rs; Nédélec & Foethke, *New J.
//! Phys.* 9, 427 (2007)), each step solves
//!
//! (γ/dt·I + K̃)·Δx = F(x) + √(2·kT·γ/dt)·ξ,   x ← x + Δx,
//!
//! with K̃ the energy Hessian made positive semi-definite term by term, by
//! conjugate gradients with a Jacobi preconditioner D⁻¹ from the Jacobi step
//! Δx₀ = D⁻¹b, to the relative residual |b − AΔx|/|b| ≤ tolerance, as
//! faer's CG does on the CPU. The blocks are the CPU's
//! (src/backend/stiffness.rs), computed on the device in f32 after the
//! force pass of each step:
//!
//! - **Bonds**: max(E″, 0)·ûûᵀ + max(E′/r, 0)·(I − ûûᵀ), with E″ from the
//!   law's `NAME_curvature` (shaders/interactions/NAME.wgsl), once per
//!   bond end (both ends compute the same bits: the separation is an exact
//!   fixed-point difference rounded once, and the block is even in it).
//! - **Angles**: the law's exact 9×9 Hessian (`NAME_hessian`) projected onto
//!   its positive semi-definite part by cyclic Jacobi rotations. The CPU
//!   takes the same Hessian by central differences of the analytic forces
//!   (relative error ~1e-10) and projects it with an eigensolver, so the two
//!   differ by the f32 rounding only.
//! - **Externals**: the law's 3×3 Hessian (`NAME_hessian`), positive
//!   semi-definite as written (a wall's k·n̂n̂ᵀ inside it, 0 for a constant
//!   force) or its positive part written out (an indenter's 2K(R − r)·ûûᵀ,
//!   without the negative transverse −K(R − r)²/r the CPU's projection drops).
//! - **Volume elements**: the element's exact 12×12 Hessian
//!   V_0·Σ_AB g_c\[A\]·g_d\[B\]·∂²W/∂F_αA∂F_βB (g_k the rows of D_m⁻¹, g_0 their
//!   negative sum), with ∂²W/∂F∂F from the law's `NAME_tetra_hessian`,
//!   projected like the angles' (kernel `implicit_tetras`; the CPU takes it
//!   by central differences of the element's forces); each product gathers a
//!   particle's rows through the forces' node → (element, corner) slots.
//! - **Body surfaces** (per-face laws): each face's 9×9 stencil of each
//!   term (`NAME_face_hessian`: γ·∇²A_t for `surface_tension`,
//!   (k_l/a0)·∇A_t∇A_tᵀ + (dE/dA_t)·∇²A_t for `area_conservation`, the exact
//!   Hessian of `surface_shear`'s face energy), projected term by term as on
//!   the CPU and summed (kernel `implicit_faces`), gathered through the
//!   forces' node → face-corner slots; and the Gauss–Newton terms over a
//!   whole body, w_V·∇V∇Vᵀ (`turgor`: K/V0, `turgor_log`: K/V) and
//!   w_A·∇A∇Aᵀ (the global area term: k_a/A0), weights from
//!   `NAME_body_weights`, applied rank one as the CPU's `SystemMatrix` does:
//!   before each product one invocation per body sums ∇V·v and ∇A·v face by
//!   face, in order, and each node adds w·(g·v)·∂g/∂x_i over its faces. The
//!   Jacobi diagonal takes w·g_i², g_i summed over the node's faces.
//! - **Body curvature** (`helfrich_bending`): per node k the generalised
//!   Gauss–Newton term w_k·g_k g_kᵀ over its one-ring, g_k = ∇M_k − β_k·∇A_k
//!   (w, β from `NAME_node_weights` at the node's M and A, kernel
//!   `implicit_nodes`), applied matrix-free like the bodies' terms: before
//!   each product one invocation per node sums g_k·v over its edges
//!   (¼∂(ℓθ)) and faces (⅓∇A_t), and each particle gathers w_k·(g_k·v)·g_k
//!   through its edge and face-corner slots. The Jacobi diagonal leaves out
//!   the cross terms between one node's edge and face contributions (a
//!   preconditioner: it changes the iterations, not the solution). One
//!   curvature term per body.
//! - **Contact between bodies** (shaders/common/implicit_contact.wgsl): each
//!   node–face pair in range adds the CPU's Gauss–Newton term c·g gᵀ,
//!   g = (n̂, −w_0·n̂, −w_1·n̂, −w_2·n̂) over (node, corners) at its closest
//!   point (src/backend/contact_mesh.rs, `push_pair_blocks`), with
//!   c = max(Σ_rules b″(d), 0) for the node–face rules (`NAME_contact_curvature`)
//!   and c = max(ε·s″·B, 0) per area-weighted rule at the node's nearest face
//!   (`NAME_switch_curvature`; the adhesion passes keep s″ and ε·s″·B beside
//!   s′ and the pull). Applied matrix-free like the pairs: each product walks
//!   the pairs as the force pass does (`contact_forces`: the node's row, then
//!   the corner's faces against its row) and computes each pair's d, w and n̂
//!   again from its face's first corner, so the four participants see the
//!   same bits and K̃ stays symmetric. **The step clamp** follows the
//!   solve: with each contact node's limit L_i = 0.4·min(d̂, its closest
//!   distance), which the contact pass keeps (the FIRE moves' clamp reads
//!   the same, `contact_move_fraction`), the
//!   solve's workgroup min-reduces s = min(1, min_i L_i/|Δx_i|) on the bits
//!   of positive f32s (order-independent) into the step's fraction,
//!   replacing the explicit step's that the force pass left there, and
//!   `implicit_move` moves by s·Δx; `advance` records s for the clock, as
//!   for the explicit step (src/gpu/contact.rs).
//! - **Pairs**: the bonds' radial block for every rule between two
//!   neighbours (and, weighted, fractional `special_bonds` partners),
//!   computed again from the positions at each product K̃·v from the
//!   particle's neighbour-list row (no storage per pair; the row must be in
//!   one binding: a list bound in chunks stops the run).
//!
//! Fixed particles have the identity row and no couplings, as on the CPU;
//! so has each coordinate a protocol holds (`freeze`, `move`), whose
//! right-hand side is 0 (the move's `prescribe` puts it back, or moves it
//! with its group, after the solve). Ramps set their parameters before the
//! force pass, so the blocks use them.
//!
//! # Which models ([`refusal`])
//!
//! Every bond, angle, pair, external and volume-element law must have its
//! device block (a WGSL function `NAME_curvature`, `NAME_hessian` or
//! `NAME_tetra_hessian`; `harmonic`, `soft_repulsion`, `lj`, `wca`,
//! `wlc_bending`, `wall`, `indenter`, `constant_force`, `neo_hookean` and
//! `linear_elastic` have one), and every body term its face stencil and
//! body weights (`turgor`, `turgor_log`, `surface_tension`,
//! `area_conservation`, `surface_shear`) or node weights
//! (`helfrich_bending`), and every contact law its curvature
//! (`contact_barrier`, `contact_adhesion`); models with custom terms stay on
//! the CPU with the reason. Bond kinetics run: a kinetic
//! bond's block is scaled by its bound state as its force is (`bond_on`),
//! and rules the host decides (`plastic`, `maturation`, …) upload their new
//! rest lengths and scales before the next step's blocks are built.
//!
//! `solver cholesky` has no device form: its decks take quasi-static Newton
//! steps (γ/dt = 1e-6 against stiffnesses of 10²–10⁵), and the device
//! solves them by the same f32 CG, saying so in the log. From the Jacobi
//! first guess CG reaches the Newton step (on the CPU to 1e-12 of the
//! Cholesky step: tests/suite/implicit.rs), so a stage relaxes to the same
//! equilibrium within the f32 rounding of the forces (tests/suite/gpu_implicit.rs,
//! the force dipole).
//!
//! # Constrained bonds
//!
//! With `constrain`, the solve is the CPU's projected CG instead (min
//! ½ΔxᵀAΔx − bᵀΔx subject to JΔx = 0, from Δx = 0; Gould, Hribar & Nocedal
//! 2001), each projection's S = JD⁻¹Jᵀ solved by an inner Jacobi-CG in the
//! same workgroup where the CPU factorises it, and the constraint tensions
//! −λ kept for the thermo (kernel `implicit_solve_constrained`,
//! shaders/common/implicit_constraints.wgsl); the
//! device's SHAKE (src/gpu/shake.rs) then projects as after every step.
//!
//! # Determinism and the read-back
//!
//! The CG runs in ONE workgroup (`implicit_solve`) by default: each product
//! K̃·v is gathered per particle from its own bond ends, externals and angle
//! slots in a fixed order, and each dot product is a fixed pairwise tree
//! over the workgroup, so the same run gives the same bits (no atomics on
//! floats). One workgroup has workgroup barriers, so the convergence test
//! is taken on the device every iteration and nothing is read back per step
//! or per iteration: the host reads the last step's iterations and residual
//! (16 bytes) at its synchronisations, for the thermo's `solver_iterations`
//! and `solver_residual`. A solve that does not converge within
//! `max_iterations` halts the run before that step is taken
//! (the host reports the step, the residual and the iterations). The cost:
//! one workgroup runs the solve on one compute unit, which suits filaments
//! and networks of up to ~10⁴ particles.
//!
//! Larger systems take the **split solve** (src/gpu/implicit_split.rs,
//! shaders/common/implicit_split.wgsl): the same CG with one dispatch per
//! phase over every workgroup, its dot products summed per workgroup by a
//! fixed tree and then over the workgroups in a fixed order (the same bits
//! on every run, not the one-workgroup solve's), a budget of iterations
//! encoded per step and a step that outruns it taken again with a larger
//! one. `integrator implicit … gpu_workgroups one|all|auto` chooses; `auto`
//! (the default) splits from [`SPLIT_SOLVE_FROM`] particles on, except with
//! constrained bonds, whose projected solve runs in one workgroup only.
//!
//! # Precision
//!
//! f32 residuals stop decreasing near ε_f32·κ(A)·|b|, so the CPU's default
//! relative tolerance 1e-10 is out of reach: the device solves to
//! max(tolerance, [`F32_TOLERANCE`]) and says so in the log when it raises
//! the deck's tolerance. The step then differs from the CPU's by about
//! κ(A)·[`F32_TOLERANCE`] relative at most, in practice the f32 rounding of
//! forces and blocks (measured in tests/suite/gpu_implicit.rs).

use wgpu::util::DeviceExt;

use super::context::{GpuContext, WORKGROUP};
use super::implicit_split::SplitSolve;
use super::pack::push_csr;
use super::prelude::implicit::*;
use super::prelude::implicit_split::SPLIT_PARTIALS;
use super::shader;
use super::side_group::SideGroup;
use super::step::{Dispatcher, Over, Phase, StepFeature};
use crate::integrate::implicit::{GpuWorkgroups, ImplicitSettings, SolveReport};
use crate::interactions::{Law, SurfaceGpu, REGISTRY};
use crate::system::Model;

/// The smallest relative residual the device's f32 conjugate gradients are
/// asked for (ε_f32 ≈ 6e-8, times the condition numbers of the filament
/// decks' systems, ~10³, leaves a margin of ten).
pub const F32_TOLERANCE: f64 = 1e-6;

/// `gpu_workgroups auto` splits the solve over every workgroup from this many
/// particles on (a round figure, not measured on hardware: below it one
/// workgroup loops over ≤ 32 particles per invocation per product).
pub const SPLIT_SOLVE_FROM: usize = 8192;

const HEADER_WORDS: usize = 22;
/// `imp` entries per particle (Δx, r, z, p, A·p, the Jacobi diagonal).
const PARTICLE_VECTORS: usize = 6;

/// Why the model's implicit step cannot run on the device (None: it can).
pub fn refusal(model: &Model) -> Option<&'static str> {
    if !model.contact_rules.iter().all(|r| stiffness_function(r.interaction).is_some()) {
        return Some(
            "`integrator implicit` with a contact law that has no GPU stiffness block runs on the CPU backend only \
             (contact_barrier and contact_adhesion have one)",
        );
    }
    if !model.body_rules.iter().all(|r| stiffness_function(r.interaction).is_some()) {
        return Some(
            "`integrator implicit` with a body term that has no GPU stiffness block runs on the CPU backend only \
             (turgor, turgor_log, surface_tension, area_conservation, surface_shear and helfrich_bending have one; custom body terms not)",
        );
    }
    let curvature = |r: usize| matches!(model.body_rules[r].interaction.law(), Law::Surface { gpu: SurfaceGpu::NodeCurvature, .. });
    if (0..model.bodies.len()).any(|b| model.rules_of_body(b).filter(|&r| curvature(r)).count() > 1) {
        return Some("`integrator implicit` with two curvature terms on one body runs on the CPU backend only (the device keeps one Gauss–Newton term per node)");
    }
    let kinds = super::custom::gpu_kinds(model);
    let tetras = model.tetra_types.iter().map(|t| t.term().interaction);
    if !kinds.iter().all(|&k| REGISTRY.get(k as usize).is_some_and(|i| stiffness_function(*i).is_some()))
        || !tetras.into_iter().all(|i| stiffness_function(i).is_some())
    {
        return Some(
            "`integrator implicit` with a bond, angle, pair, external or volume-element law that has no GPU stiffness block runs on the CPU backend only \
             (harmonic, soft_repulsion, lj, wca, wlc_bending, wall, indenter, constant_force, neo_hookean and linear_elastic have one)",
        );
    }
    None
}

/// Whether the solve is split over every workgroup (`gpu_workgroups`, `n`
/// particles, constrained bonds or not).
fn splits(choice: GpuWorkgroups, n: usize, constrained: bool) -> Result<bool, String> {
    match choice {
        GpuWorkgroups::One => Ok(false),
        GpuWorkgroups::All if constrained => {
            Err("`gpu_workgroups all` with `constrain`: the device's projected solve runs in one workgroup \
                                                  (use `gpu_workgroups one` or `auto`)"
                .into())
        }
        GpuWorkgroups::All => Ok(true),
        GpuWorkgroups::Auto => Ok(n >= SPLIT_SOLVE_FROM && !constrained),
    }
}

/// The WGSL function giving an interaction's stiffness, if its evaluator
/// file has one: `NAME_curvature` (E″ of a radial law), `NAME_hessian`
/// (a three- or one-body law's Hessian), `NAME_tetra_hessian` (a volume
/// element's ∂²W/∂F∂F) or, for a per-face body law, `NAME_face_hessian`
/// (its 9×9 stencil on one face) with `NAME_body_weights` (the weights of
/// its Gauss–Newton terms over the whole body, on ∇V∇Vᵀ and ∇A∇Aᵀ), or, for
/// a curvature law, `NAME_node_weights` (w and β of its Gauss–Newton term
/// w·g gᵀ per node, g = ∇M_i − β·∇A_i), or, for contact between bodies,
/// `NAME_contact_curvature` (b″ of a node–face law) or
/// `NAME_switch_curvature` (s″ of an area-weighted law's switch).
fn stiffness_function(interaction: &dyn crate::interactions::Interaction) -> Option<String> {
    let name = interaction.name();
    let functions = match interaction.law() {
        Law::Radial { .. } => vec![format!("{name}_curvature")],
        Law::ThreeBody(_) | Law::OneBody(_) => vec![format!("{name}_hessian")],
        Law::Tetra(_) => vec![format!("{name}_tetra_hessian")],
        Law::Surface { gpu: SurfaceGpu::PerFace, .. } => vec![format!("{name}_face_hessian"), format!("{name}_body_weights")],
        Law::Surface { gpu: SurfaceGpu::NodeCurvature, .. } => vec![format!("{name}_node_weights")],
        Law::Contact { .. } => vec![format!("{name}_contact_curvature")],
        Law::ContactArea { .. } => vec![format!("{name}_switch_curvature")],
        _ => return None,
    };
    let source = shader::interaction_source(name)?;
    functions.iter().all(|f| source.contains(&format!("fn {f}("))).then(|| functions[0].clone())
}

/// The stiffness dispatch functions over the registry: `radial_curvature`,
/// `three_body_hessian`, `one_body_hessian`, `tetra_hessian`, `face_hessian`,
/// `body_weights`, `node_weights`, `contact_curvature` and
/// `contact_area_switch_curvature` (0 for laws without one, which
/// [`refusal`] keeps off the device).
pub fn stiffness_dispatch() -> String {
    let mut radial = String::from("fn radial_curvature(kind: u32, p: array<f32, 8>, r: f32) -> f32 {\n    switch kind {\n");
    let mut three = String::from(
        "fn three_body_hessian(kind: u32, p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> array<f32, 81> {\n    switch kind {\n",
    );
    let mut one = String::from("fn one_body_hessian(kind: u32, p: array<f32, 8>, x: vec3<f32>) -> mat3x3<f32> {\n    switch kind {\n");
    let mut tetra = String::from(
        "fn tetra_hessian(kind: u32, p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> array<f32, 81> {\n    switch kind {\n",
    );
    let mut face = String::from(
        "fn face_hessian(kind: u32, p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> array<f32, 81> {\n    switch kind {\n",
    );
    let mut weights = String::from("fn body_weights(kind: u32, p: array<f32, 8>, body: BodyTotals) -> vec2<f32> {\n    switch kind {\n");
    let mut node = String::from("fn node_weights(kind: u32, p: array<f32, 8>, m: f32, a: f32) -> vec2<f32> {\n    switch kind {\n");
    let mut contact = String::from("fn contact_curvature(kind: u32, p: array<f32, 8>, d: f32) -> f32 {\n    switch kind {\n");
    let mut area = String::from("fn contact_area_switch_curvature(kind: u32, p: array<f32, 8>, d: f32) -> f32 {\n    switch kind {\n");
    for (index, interaction) in REGISTRY.iter().enumerate() {
        let Some(function) = stiffness_function(*interaction) else { continue };
        let (out, args) = match interaction.law() {
            Law::Radial { .. } => (&mut radial, "p, r"),
            Law::ThreeBody(_) => (&mut three, "p, ri, rj, rk"),
            Law::Tetra(_) => (&mut tetra, "p, f, j, f_inv_t"),
            Law::Surface { gpu: SurfaceGpu::PerFace, .. } => {
                let name = interaction.name();
                weights.push_str(&format!("        case {index}u: {{ return {name}_body_weights(p, body); }}\n"));
                (&mut face, "p, body, g")
            }
            Law::Surface { .. } => (&mut node, "p, m, a"),
            Law::Contact { .. } => (&mut contact, "p, d"),
            Law::ContactArea { .. } => (&mut area, "p, d"),
            _ => (&mut one, "p, x"),
        };
        out.push_str(&format!("        case {index}u: {{ return {function}({args}); }}\n"));
    }
    radial.push_str("        default: { return 0.0; }\n    }\n}\n");
    three.push_str("        default: { return array<f32, 81>(); }\n    }\n}\n");
    one.push_str("        default: { return mat3x3<f32>(); }\n    }\n}\n");
    tetra.push_str("        default: { return array<f32, 81>(); }\n    }\n}\n");
    face.push_str("        default: { return array<f32, 81>(); }\n    }\n}\n");
    weights.push_str("        default: { return vec2<f32>(0.0); }\n    }\n}\n");
    node.push_str("        default: { return vec2<f32>(0.0); }\n    }\n}\n");
    contact.push_str("        default: { return 0.0; }\n    }\n}\n");
    area.push_str("        default: { return 0.0; }\n    }\n}\n");
    radial + &three + &one + &tetra + &face + &weights + &node + &contact + &area
}

/// The conjugate gradients: in one workgroup (`implicit_solve` or, with
/// constraints, `implicit_solve_constrained`), or split over every workgroup
/// (src/gpu/implicit_split.rs).
enum Solve {
    One(wgpu::ComputePipeline),
    Split(SplitSolve),
}

/// A per-term block kernel of the implicit step and the terms it runs over.
struct TermBlocks {
    kernel: wgpu::ComputePipeline,
    count: u32,
}

/// The device's implicit solver: its buffers, bind group (group 1) and kernels.
pub(super) struct ImplicitSolver {
    pub(super) group: wgpu::BindGroup,
    /// The block kernels of the angles, volume elements, faces and curvature nodes.
    terms: [TermBlocks; 4],
    blocks: wgpu::ComputePipeline,
    solve: Solve,
    moves: wgpu::ComputePipeline,
    /// The `imp` buffer and the byte offset of its report entry.
    pub(super) buffer: wgpu::Buffer,
    pub(super) report_at: u64,
    particles: u32,
    /// Curvature nodes and bodies of the surface terms (the split solve's body dots).
    body_items: u32,
    /// Constrained bonds, and the byte offset of their entries in `imp`.
    pub(super) constraints: usize,
    pub(super) constraints_at: u64,
    /// The relative residual the device solves to.
    tolerance: f64,
    max_iterations: usize,
}

impl ImplicitSolver {
    /// Packs the angle slots and per-type factors, and compiles the kernels
    /// against the backend's main bind group layout.
    pub(super) fn new(
        ctx: &GpuContext,
        main_layout: &wgpu::BindGroupLayout,
        model: &Model,
        (dt, kt): (f64, f64),
        implicit: &ImplicitSettings,
        constrained: &[[u32; 2]],
    ) -> Result<Self, String> {
        if let Some(why) = refusal(model) {
            return Err(why.into());
        }
        let n = model.len();
        let tolerance = implicit.tolerance.max(F32_TOLERANCE);
        let angle_base = model.bond_types.len();
        let mut header = vec![0u32; HEADER_WORDS];
        let mut words = Vec::new();
        header[IMP_ANGLES] = model.angles.len() as u32;
        header[IMP_OFF_ANGLES] = HEADER_WORDS as u32;
        let mut slot_rows = vec![Vec::new(); n];
        for (a, &[i, j, k]) in model.angles.iter().enumerate() {
            words.extend([i, j, k, (angle_base + model.angle_type[a] as usize) as u32]);
            for (role, p) in [i, j, k].into_iter().enumerate() {
                slot_rows[p as usize].push([a as u32, role as u32]);
            }
        }
        let (mut starts, mut slots) = (Vec::new(), Vec::new());
        push_csr(&slot_rows, &mut starts, &mut slots);
        header[IMP_OFF_SLOT_START] = (HEADER_WORDS + words.len()) as u32;
        words.extend(&starts);
        header[IMP_OFF_SLOTS] = (HEADER_WORDS + words.len()) as u32;
        words.extend(slots.iter().flatten());
        header[IMP_MAX_ITER] = implicit.max_iterations.min(u32::MAX as usize) as u32;
        header[IMP_TOLERANCE] = (tolerance as f32).to_bits();
        let drag = |g: f64| if g.is_finite() { (g / dt) as f32 } else { 0.0 };
        let kick = |g: f64| if g.is_finite() && kt > 0.0 { (2.0 * kt * g / dt).sqrt() as f32 } else { 0.0 };
        header[IMP_OFF_DRAG] = (HEADER_WORDS + words.len()) as u32;
        words.extend(model.type_drag.iter().map(|&g| drag(g).to_bits()));
        header[IMP_OFF_KICK] = (HEADER_WORDS + words.len()) as u32;
        words.extend(model.type_drag.iter().map(|&g| kick(g).to_bits()));
        // `imp`: the particle vectors, then 2 entries per bond end and per
        // external entry, 21 per angle, 36 per volume element, 21 per face,
        // 1 per body and 1 per curvature node of the surface terms (in the
        // surface pack's order, src/gpu/surface.rs), then the report.
        let externals: usize = model.externals.iter().map(|e| e.members.len()).sum();
        let bonds_at = PARTICLE_VECTORS * n;
        let externals_at = bonds_at + 2 * 2 * model.bonds.len();
        let angles_at = externals_at + 2 * externals;
        let tetras_at = angles_at + ANGLE_VEC4 * model.angles.len();
        let faces_at = tetras_at + TETRA_VEC4 * model.tetras.len();
        let (faces, bodies, body_nodes) = super::surface::packed_counts(model);
        let bodies_at = faces_at + FACE_VEC4 * faces;
        let nodes_at = bodies_at + bodies;
        let report = nodes_at + body_nodes;
        header[IMP_V_TETRAS] = tetras_at as u32;
        header[IMP_V_FACES] = faces_at as u32;
        header[IMP_V_BODIES] = bodies_at as u32;
        header[IMP_V_NODES] = nodes_at as u32;
        header[IMP_V_BONDS] = bonds_at as u32;
        header[IMP_V_EXTERNALS] = externals_at as u32;
        header[IMP_V_ANGLES] = angles_at as u32;
        header[IMP_V_REPORT] = report as u32;
        // Constrained bonds (shaders/common/implicit_constraints.wgsl):
        // their ends, and each particle's slots (constraint, J_END where it is j).
        header[IMP_CONSTRAINTS] = constrained.len() as u32;
        header[IMP_OFF_CONSTRAINTS] = (HEADER_WORDS + words.len()) as u32;
        words.extend(constrained.iter().flatten());
        let mut constraint_rows = vec![Vec::new(); n];
        for (k, &[i, j]) in constrained.iter().enumerate() {
            constraint_rows[i as usize].push(k as u32);
            constraint_rows[j as usize].push(k as u32 | J_END);
        }
        let (mut starts, mut slots) = (Vec::new(), Vec::new());
        push_csr(&constraint_rows, &mut starts, &mut slots);
        header[IMP_OFF_CSLOT_START] = (HEADER_WORDS + words.len()) as u32;
        words.extend(&starts);
        header[IMP_OFF_CSLOTS] = (HEADER_WORDS + words.len()) as u32;
        words.extend(&slots);
        header[IMP_V_CONSTRAINTS] = (report + 1) as u32;
        // The split solve's scalars and one partial sum per workgroup
        // (shaders/common/implicit_split.wgsl), after the constraints'.
        let split_at = report + 1 + CONSTRAINT_VEC4 * constrained.len();
        header[IMP_V_SPLIT] = split_at as u32;
        let topo: Vec<u32> = header.into_iter().chain(words).collect();
        let entries = (split_at + SPLIT_PARTIALS + n.div_ceil(WORKGROUP as usize)) as u64;
        let limit = ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size);
        if 16 * entries > limit || entries > u32::MAX as u64 {
            return Err(format!(
                "the implicit solver's vectors and blocks need {:.0} MiB, more than one storage binding",
                16.0 * entries as f64 / 1048576.0
            ));
        }
        let device = &ctx.device;
        let imp_topo = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("imp_topo"),
            contents: bytemuck::cast_slice(&topo),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("imp"),
            size: 16 * entries,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let side = SideGroup::new(ctx, main_layout, model, "the implicit step", &[(1, true, &imp_topo), (2, false, &buffer)])?;
        let split = splits(implicit.gpu_workgroups, n, !constrained.is_empty())?;
        // Only the solve kernels the model uses: llvmpipe compiles a kernel at its first dispatch.
        let solve = if split {
            Solve::Split(SplitSolve::new(&side, ctx, bodies > 0, !model.contact_rules.is_empty(), implicit.max_iterations))
        } else {
            Solve::One(side.pipeline(ctx, if constrained.is_empty() { "implicit_solve" } else { "implicit_solve_constrained" }))
        };
        Ok(Self {
            terms: [
                ("implicit_angles", model.angles.len()),
                ("implicit_tetras", model.tetras.len()),
                ("implicit_faces", faces),
                ("implicit_nodes", body_nodes),
            ]
            .map(|(kernel, count)| TermBlocks { kernel: side.pipeline(ctx, kernel), count: count as u32 }),
            blocks: side.pipeline(ctx, "implicit_blocks"),
            solve,
            moves: side.pipeline(ctx, "implicit_move"),
            group: side.group,
            buffer,
            report_at: 16 * report as u64,
            particles: n as u32,
            body_items: body_nodes.max(bodies) as u32,
            constraints: constrained.len(),
            constraints_at: 16 * (report + 1) as u64,
            tolerance,
            max_iterations: implicit.max_iterations,
        })
    }

    /// The step's kernels in order with their workgroups: the per-term
    /// block kernels that have terms (angles, volume elements, faces,
    /// curvature nodes), the per-particle blocks, the solve and the move.
    pub(super) fn step_passes(&self) -> Vec<(&wgpu::ComputePipeline, u32)> {
        let particles = self.particles.div_ceil(WORKGROUP);
        let mut passes: Vec<_> = self.terms.iter().filter(|t| t.count > 0).map(|t| (&t.kernel, t.count.div_ceil(WORKGROUP))).collect();
        passes.push((&self.blocks, particles));
        match &self.solve {
            Solve::One(kernel) => passes.push((kernel, 1)),
            Solve::Split(split) => passes.extend(split.passes(particles, self.body_items.div_ceil(WORKGROUP))),
        }
        passes.push((&self.moves, particles));
        passes
    }

    pub(super) fn is_split(&self) -> bool {
        matches!(self.solve, Solve::Split(_))
    }

    /// The split solve, if the step runs it.
    pub(super) fn split_mut(&mut self) -> Option<&mut SplitSolve> {
        match &mut self.solve {
            Solve::One(_) => None,
            Solve::Split(split) => Some(split),
        }
    }

    /// The most iterations a step's split solve took since the host last
    /// cleared the report's third word, from the report's 16 bytes.
    pub(super) fn most_iterations(bytes: &[u8]) -> usize {
        let entry: [f32; 4] = bytemuck::pod_read_unaligned(&bytes[..16]);
        entry[2].to_bits() as usize
    }

    /// The last solve's report, from the 16 bytes of its entry.
    pub(super) fn report(&self, bytes: &[u8]) -> SolveReport {
        let entry: [f32; 4] = bytemuck::pod_read_unaligned(&bytes[..16]);
        SolveReport { iterations: entry[0].to_bits() as usize, relative_residual: f64::from(entry[1]), step_fraction: 1.0 }
    }

    /// The constraint tensions of the last solve (the deck's list order),
    /// from the constraints' `imp` entries.
    pub(super) fn constraint_tensions(&self, bytes: &[u8]) -> Vec<f64> {
        let entries: &[[f32; 4]] = bytemuck::cast_slice(bytes);
        entries.chunks(CONSTRAINT_VEC4).map(|c| f64::from(c[2][2])).collect()
    }

    /// Why a solve halted the run.
    pub(super) fn failure(&self, report: &SolveReport) -> String {
        format!(
            "integrator implicit: the device's conjugate gradients reached relative residual {:e} after {} iterations \
             (tolerance {:e}, max_iterations {})",
            report.relative_residual, report.iterations, self.tolerance, self.max_iterations
        )
    }
}

impl StepFeature for ImplicitSolver {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        if phase == Phase::Move {
            pass.set_bind_group(1, &self.group, &[]);
            for (kernel, groups) in self.step_passes() {
                at.dispatch(pass, kernel, Over::Groups(groups));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_splits_large_unconstrained_solves() {
        let auto = |n, constrained| splits(GpuWorkgroups::Auto, n, constrained).unwrap();
        assert!(!auto(SPLIT_SOLVE_FROM - 1, false) && auto(SPLIT_SOLVE_FROM, false) && !auto(10 * SPLIT_SOLVE_FROM, true));
        assert!(!splits(GpuWorkgroups::One, 1 << 20, false).unwrap() && splits(GpuWorkgroups::All, 10, false).unwrap());
        assert!(splits(GpuWorkgroups::All, 10, true).unwrap_err().contains("constrain"));
    }
}
