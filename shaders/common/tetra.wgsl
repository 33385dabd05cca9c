// Volume elements (linear tetrahedra, `[ tetrahedra ]`), in one pass before
// `forces` gathers each particle's corner slots (src/gpu/tetra.rs). No
// float atomics: each element writes its own four slots of `surf`, and each
// particle sums its slots in ascending element order.
//
// `tetra_law` dispatches on the registry index of the element's interaction
// type to `NAME_tetra` (shaders/interactions/NAME.wgsl); it is generated
// from the registry when the shader is composed.

// TETRA_WORDS (the words of an element record in `topo`: corners 0–3
// (particles), 4 its term) and TETRA_REST_FLOATS (an element's rest shape in
// `fparams`: D_m⁻¹ by columns, then V_0) are the prelude's (src/gpu/prelude.rs).

// A strain-energy density W at F and its first Piola stress P = ∂W/∂F.
struct TetraDensity {
    w: f32,
    piola: mat3x3<f32>,
}

// Lamé's constants (μ, λ) of Young's modulus E and Poisson's ratio ν.
fn lame_constants(e: f32, nu: f32) -> vec2<f32> {
    return vec2<f32>(e / (2.0 * (1.0 + nu)), e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)));
}

// An element's deformation: F = D_s·D_m⁻¹ with the corners 1–3 at their
// minimum images from corner 0 (as on the CPU), J = det F, the cofactor
// matrix J·F⁻ᵀ = [f₁ × f₂, f₂ × f₀, f₀ × f₁] (f_k the columns of F), its
// rest shape (D_m⁻¹, V_0) and its term.
struct TetraShape {
    f: mat3x3<f32>,
    j: f32,
    cofactor: mat3x3<f32>,
    dm_inv: mat3x3<f32>,
    v0: f32,
    term: u32,
}

fn tetra_shape(e: u32) -> TetraShape {
    let at = P.off_tetras + TETRA_WORDS * e;
    let c0 = topo[at];
    let ds = mat3x3<f32>(separation(c0, topo[at + 1u]), separation(c0, topo[at + 2u]), separation(c0, topo[at + 3u]));
    let r = P.off_tetra_rest + TETRA_REST_FLOATS * e;
    let dm_inv = mat3x3<f32>(
        vec3<f32>(fparams[r], fparams[r + 1u], fparams[r + 2u]),
        vec3<f32>(fparams[r + 3u], fparams[r + 4u], fparams[r + 5u]),
        vec3<f32>(fparams[r + 6u], fparams[r + 7u], fparams[r + 8u]),
    );
    let f = ds * dm_inv;
    let cofactor = mat3x3<f32>(cross(f[1], f[2]), cross(f[2], f[0]), cross(f[0], f[1]));
    return TetraShape(f, dot(f[0], cofactor[0]), cofactor, dm_inv, fparams[r + 9u], topo[at + 4u]);
}

// One invocation per element: its shape (`tetra_shape`), the law's W and P
// at F, and the corner forces [f_1 f_2 f_3] = −V_0·P·D_m⁻ᵀ,
// f_0 = −(f_1 + f_2 + f_3), each with a quarter of V_0·W. An element turned
// inside out or flat (J ≤ 0) has no elastic energy (the CPU's is NaN): its
// corners get forces too large for any step, so the step is refused and
// the run stops with a blow-up report.
@compute @workgroup_size(256)
fn tetra_forces(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let e = linear_index(wg, local);
    if e >= P.n_tetras || halted() {
        return;
    }
    let shape = tetra_shape(e);
    var forces = array<vec3<f32>, 4>(vec3<f32>(3.0e38), vec3<f32>(3.0e38), vec3<f32>(3.0e38), vec3<f32>(3.0e38));
    var energy = 0.0;
    if shape.j > 0.0 {
        let density = tetra_law(topo[P.off_term_kind + shape.term], term_params(shape.term), shape.f, shape.j, shape.cofactor * (1.0 / shape.j));
        let h = (-shape.v0) * density.piola * transpose(shape.dm_inv);
        forces = array<vec3<f32>, 4>(-(h[0] + h[1] + h[2]), h[0], h[1], h[2]);
        energy = 0.25 * shape.v0 * density.w;
    }
    let slots = P.tetra_surf_base + 4u * e;
    for (var k = 0u; k < 4u; k++) {
        surf[slots + k] = vec4<f32>(forces[k], energy);
    }
}
