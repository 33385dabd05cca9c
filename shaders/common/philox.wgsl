// Philox4x32-10 (Salmon et al., SC'11), the same generator and layout as the
// CPU's src/integrate/rng.rs: counter = [id, stream, step_lo, step_hi],
// key = [seed_lo, seed_hi]. WGSL has no 64-bit integers, so the 32×32 → 64
// products are assembled from 16-bit halves; the words are bit-identical to
// the CPU's. PHILOX_M0, PHILOX_M1, PHILOX_W0, PHILOX_W1, the noise streams
// and SQRT_12 are the prelude's (src/gpu/prelude.rs, from src/rng.rs).

// (high, low) words of a · b.
fn mulhilo(a: u32, b: u32) -> vec2<u32> {
    let a_lo = a & 0xFFFFu;
    let a_hi = a >> 16u;
    let b_lo = b & 0xFFFFu;
    let b_hi = b >> 16u;
    let ll = a_lo * b_lo;
    let lh = a_lo * b_hi;
    let hl = a_hi * b_lo;
    let hh = a_hi * b_hi;
    let mid = (ll >> 16u) + (lh & 0xFFFFu) + (hl & 0xFFFFu);
    let hi = hh + (lh >> 16u) + (hl >> 16u) + (mid >> 16u);
    return vec2<u32>(hi, a * b);
}

fn philox4x32_10(counter: vec4<u32>, key: vec2<u32>) -> vec4<u32> {
    var c = counter;
    var k = key;
    for (var round = 0u; round < 10u; round++) {
        if round > 0u {
            k = k + vec2<u32>(PHILOX_W0, PHILOX_W1);
        }
        let p0 = mulhilo(PHILOX_M0, c.x);
        let p1 = mulhilo(PHILOX_M1, c.z);
        c = vec4<u32>(p1.x ^ c.y ^ k.x, p1.y, p0.x ^ c.w ^ k.y, p0.y);
    }
    return c;
}

// Three zero-mean, unit-variance uniforms on (−√3, √3) from stream 0, as
// `noise uniform` on the CPU: the top 24 bits of each word, so that the f32
// value is exact (the CPU uses all 32 bits in f64; the two differ by < 2⁻²⁴·√12).
fn noise3(seed: vec2<u32>, step: vec2<u32>, id: u32) -> vec3<f32> {
    let w = philox4x32_10(vec4<u32>(id, STREAM_NOISE, step.x, step.y), seed);
    let u = (vec3<f32>(vec3<u32>(w.x, w.y, w.z) >> vec3<u32>(8u)) + 0.5) * (1.0 / 16777216.0) - 0.5;
    return u * SQRT_12;
}

// A uniform on (0, 1) from the top 24 bits of a word (never 0 or 1).
fn open_unit(word: u32) -> f32 {
    return (f32(word >> 8u) + 0.5) * (1.0 / 16777216.0);
}

// Three standard normals by Box–Muller from streams 0 and 1, as `noise
// gaussian` on the CPU (same words; f32 and WGSL's ln/sin/cos, so the same
// distribution but not the same bits).
fn gaussian3(seed: vec2<u32>, step: vec2<u32>, id: u32) -> vec3<f32> {
    let a = philox4x32_10(vec4<u32>(id, STREAM_NOISE, step.x, step.y), seed);
    let b = philox4x32_10(vec4<u32>(id, STREAM_NOISE_GAUSSIAN, step.x, step.y), seed);
    let r = sqrt(-2.0 * log(open_unit(a.x)));
    let angle = 6.283185307179586 * open_unit(a.z);
    let r2 = sqrt(-2.0 * log(open_unit(b.x)));
    return vec3<f32>(r * cos(angle), r * sin(angle), r2 * cos(6.283185307179586 * open_unit(b.z)));
}
