//! Counter-based random numbers: Philox4x32-10 keyed by (seed, step, id, stream).
//!
//! # Generator
//!
//! Philox4x32-10 (Salmon, Moraes, Dror & Shaw, *Parallel random numbers: as
//! easy as 1, 2, 3*, SC'11) maps a 128-bit counter `c = (c0, c1, c2, c3)` and
//! a 64-bit key `k = (k0, k1)` to 128 random bits with ten rounds of
//!
//! ```text
//! (hi0, lo0) = M0 · c0          (32×32 → 64-bit product)
//! (hi1, lo1) = M1 · c2
//! c ← (hi1 ⊕ c1 ⊕ k0,  lo1,  hi0 ⊕ c3 ⊕ k1,  lo0)
//! k ← (k0 + W0, k1 + W1)        (between rounds, mod 2³²)
//! ```
//!
//! with `M0 = 0xD2511F53`, `M1 = 0xCD9E8D57`, `W0 = 0x9E3779B9`,
//! `W1 = 0xBB67AE85`. It is checked against the Random123 known-answer vectors.
//!
//! There is no generator state: the numbers for particle `id` at step `step`
//! are a pure function of `(seed, step, id, stream)`, so they are the same on
//! the CPU and the GPU, for any thread count, decomposition or restart
//! (HOOMD-blue's scheme, convention 8).
//!
//! # Layout
//!
//! `counter = [id, stream, step_lo, step_hi]`, `key = [seed_lo, seed_hi]`
//! (the `_lo`/`_hi` halves of a `u64`). Streams 0 and 1 belong to the
//! Brownian noise of [`noise3`]; other consumers (e.g. bond kinetics) take
//! their own stream numbers from 2 upwards ([`block`]).
//!
//! # Noise
//!
//! [`noise3`] gives three numbers of zero mean and unit variance:
//!
//! * [`Noise::Uniform`] (the default): the first three words `x` of block
//!   (stream 0) become `u = ((x + ½)/2³² − ½)·√12`, uniform on
//!   `(−√3, √3)`. Only `+ − ×` on exactly representable values: no
//!   transcendentals, so the WGSL port reproduces it bit for bit. For
//!   overdamped Euler–Maruyama only the first two moments matter in the
//!   small-step limit (the increments' sum over many steps is Gaussian by the
//!   central limit theorem), so this is the standard choice of HOOMD-blue
//!   and LAMMPS `fix brownian`.
//! * [`Noise::Gaussian`]: Box–Muller from two blocks (streams 0 and 1). Each
//!   pair of words `(a, b)` gives a 52-bit uniform
//!   `u = ((a·2²⁰ + ⌊b/2¹²⌋) + ½)·2⁻⁵² ∈ (0, 1)` (exact in f64, never 0 or 1); with `u1..u4` from the eight
//!   words, `r = √(−2 ln u1)`, `n0 = r cos 2πu2`, `n1 = r sin 2πu2`, and
//!   `n2 = √(−2 ln u3)·cos 2πu4`. Exact normals, but `ln/cos/sin` are not
//!   bit-identical across platforms.

use std::f64::consts::TAU;

/// Philox multiplier for word 0.
pub const PHILOX_M0: u32 = 0xD251_1F53;
/// Philox multiplier for word 2.
pub const PHILOX_M1: u32 = 0xCD9E_8D57;
/// Weyl key increment for key word 0 (golden ratio).
pub const PHILOX_W0: u32 = 0x9E37_79B9;
/// Weyl key increment for key word 1 (√3 − 1).
pub const PHILOX_W1: u32 = 0xBB67_AE85;

/// The stream of the first (uniform, or first Box–Muller) noise block.
pub const STREAM_NOISE: u32 = 0;
/// The stream of the second Box–Muller noise block.
pub const STREAM_NOISE_GAUSSIAN: u32 = 1;

/// √12: scales a zero-mean uniform on `(−½, ½)` to unit variance.
pub const SQRT_12: f64 = 3.464_101_615_137_754_5;

#[inline(always)]
fn mulhilo(a: u32, b: u32) -> (u32, u32) {
    let p = a as u64 * b as u64;
    ((p >> 32) as u32, p as u32)
}

/// Philox4x32 with 10 rounds: 128 random bits from a counter and a key.
#[inline]
pub fn philox4x32_10(counter: [u32; 4], key: [u32; 2]) -> [u32; 4] {
    let mut c = counter;
    let mut k = key;
    for round in 0..10 {
        if round > 0 {
            k[0] = k[0].wrapping_add(PHILOX_W0);
            k[1] = k[1].wrapping_add(PHILOX_W1);
        }
        let (hi0, lo0) = mulhilo(PHILOX_M0, c[0]);
        let (hi1, lo1) = mulhilo(PHILOX_M1, c[2]);
        c = [hi1 ^ c[1] ^ k[0], lo1, hi0 ^ c[3] ^ k[1], lo0];
    }
    c
}

/// [`philox4x32_10`] of four counters under one key: the same words as four
/// calls (integer arithmetic, so exactly), computed four lanes at once on a
/// CPU with AVX2, which the Brownian step's noise draws for four particles
/// per call (the scalar rounds were 9 % of the benchmark melt's instructions).
#[inline]
pub fn philox4x32_10_x4(counters: [[u32; 4]; 4], key: [u32; 2]) -> [[u32; 4]; 4] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU reported AVX2.
        return unsafe { philox4x32_10_x4_avx2(counters, key) };
    }
    counters.map(|c| philox4x32_10(c, key))
}

/// The AVX2 lanes of [`philox4x32_10_x4`]: each word of the four counters
/// in one register, a counter per 64-bit lane, its value in the low 32 bits.
/// `_mm256_mul_epu32` multiplies the low halves into the full 64-bit products
/// (hi, lo) of [`mulhilo`]; a lane's high half may hold leftover bits between
/// rounds (the products' hi words are XORed into it), which no multiply reads
/// and the final truncation drops.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn philox4x32_10_x4_avx2(counters: [[u32; 4]; 4], key: [u32; 2]) -> [[u32; 4]; 4] {
    use std::arch::x86_64::*;
    let word = |w: usize| _mm256_setr_epi64x(counters[0][w] as i64, counters[1][w] as i64, counters[2][w] as i64, counters[3][w] as i64);
    let (mut c0, mut c1, mut c2, mut c3) = (word(0), word(1), word(2), word(3));
    let (m0, m1) = (_mm256_set1_epi64x(PHILOX_M0 as i64), _mm256_set1_epi64x(PHILOX_M1 as i64));
    let mut k = key;
    for round in 0..10 {
        if round > 0 {
            k[0] = k[0].wrapping_add(PHILOX_W0);
            k[1] = k[1].wrapping_add(PHILOX_W1);
        }
        let (p0, p1) = (_mm256_mul_epu32(m0, c0), _mm256_mul_epu32(m1, c2));
        let next0 = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64::<32>(p1), c1), _mm256_set1_epi64x(k[0] as i64));
        let next2 = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64::<32>(p0), c3), _mm256_set1_epi64x(k[1] as i64));
        (c0, c1, c2, c3) = (next0, p1, next2, p0);
    }
    let mut out = [[0u32; 4]; 4];
    for (w, c) in [c0, c1, c2, c3].into_iter().enumerate() {
        let mut lanes = [0u64; 4];
        // SAFETY: `lanes` holds the register's 32 bytes.
        unsafe { _mm256_storeu_si256(lanes.as_mut_ptr().cast(), c) };
        for (l, &lane) in lanes.iter().enumerate() {
            out[l][w] = lane as u32;
        }
    }
    out
}

/// One Philox block for `(seed, step, id, stream)` in this crate's layout:
/// `counter = [id, stream, step_lo, step_hi]`, `key = [seed_lo, seed_hi]`.
#[inline]
pub fn block(seed: u64, step: u64, id: u32, stream: u32) -> [u32; 4] {
    philox4x32_10([id, stream, step as u32, (step >> 32) as u32], [seed as u32, (seed >> 32) as u32])
}

/// Distribution of the noise components.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Noise {
    /// Uniform on `(−√3, √3)`: zero mean, unit variance, bit-identical on GPU.
    #[default]
    Uniform,
    /// Standard normal by Box–Muller.
    Gaussian,
}

impl Noise {
    /// Parses a deck keyword (`uniform` or `gaussian`).
    pub fn from_keyword(word: &str) -> Option<Self> {
        match word {
            "uniform" => Some(Self::Uniform),
            "gaussian" => Some(Self::Gaussian),
            _ => None,
        }
    }
}

/// A 32-bit word as a zero-mean, unit-variance uniform: `((x + ½)/2³² − ½)·√12`.
#[inline]
pub fn uniform_unit_variance(x: u32) -> f64 {
    ((x as f64 + 0.5) * (1.0 / 4_294_967_296.0) - 0.5) * SQRT_12
}

/// Two words as a 52-bit uniform in the open interval `(0, 1)`:
/// `(k + ½)·2⁻⁵²` with `k = a·2²⁰ + ⌊b/2¹²⌋`, exact in f64 (so never 0 or 1).
#[inline]
pub fn open_unit_52(a: u32, b: u32) -> f64 {
    let k = ((a as u64) << 20) | ((b as u64) >> 12);
    (k as f64 + 0.5) * (1.0 / 4_503_599_627_370_496.0)
}

/// Three zero-mean, unit-variance random numbers for particle `id` at `step`.
#[inline]
pub fn noise3(seed: u64, step: u64, id: u32, kind: Noise) -> [f64; 3] {
    let b0 = block(seed, step, id, STREAM_NOISE);
    match kind {
        Noise::Uniform => [uniform_unit_variance(b0[0]), uniform_unit_variance(b0[1]), uniform_unit_variance(b0[2])],
        Noise::Gaussian => {
            let b1 = block(seed, step, id, STREAM_NOISE_GAUSSIAN);
            let u1 = open_unit_52(b0[0], b0[1]);
            let u2 = open_unit_52(b0[2], b0[3]);
            let u3 = open_unit_52(b1[0], b1[1]);
            let u4 = open_unit_52(b1[2], b1[3]);
            let r1 = (-2.0 * u1.ln()).sqrt();
            let (s2, c2) = (TAU * u2).sin_cos();
            let r3 = (-2.0 * u3.ln()).sqrt();
            [r1 * c2, r1 * s2, r3 * (TAU * u4).cos()]
        }
    }
}

/// [`noise3`] of particles `first`, `first + 1`, `first + 2` and
/// `first + 3`, the same bits, the uniform kind's blocks four at once
/// ([`philox4x32_10_x4`]).
#[inline]
pub fn noise3_x4(seed: u64, step: u64, first: u32, kind: Noise) -> [[f64; 3]; 4] {
    let id = |l: usize| first.wrapping_add(l as u32);
    match kind {
        Noise::Uniform => {
            let counter = |l: usize| [id(l), STREAM_NOISE, step as u32, (step >> 32) as u32];
            let blocks = philox4x32_10_x4(std::array::from_fn(counter), [seed as u32, (seed >> 32) as u32]);
            blocks.map(|b| [uniform_unit_variance(b[0]), uniform_unit_variance(b[1]), uniform_unit_variance(b[2])])
        }
        Noise::Gaussian => std::array::from_fn(|l| noise3(seed, step, id(l), kind)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random123_known_answers() {
        assert_eq!(philox4x32_10([0; 4], [0; 2]), [0x6627e8d5, 0xe169c58d, 0xbc57ac4c, 0x9b00dbd8]);
        assert_eq!(philox4x32_10([u32::MAX; 4], [u32::MAX; 2]), [0x408f276d, 0x41c83b0e, 0xa20bc7c6, 0x6d5451fd]);
        assert_eq!(
            philox4x32_10([0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344], [0xa4093822, 0x299f31d0]),
            [0xd16cfe09, 0x94fdcceb, 0x5001e420, 0x24126ea1]
        );
    }

    /// Four lanes at once are four scalar blocks, word for word, for
    /// counters and keys that set every bit (and the known answers); the
    /// noise of four particles is four particles' noise, bit for bit.
    #[test]
    fn four_lanes_are_four_blocks() {
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u32
        };
        let mut cases: Vec<([[u32; 4]; 4], [u32; 2])> =
            (0..2000).map(|_| ([(); 4].map(|_| [(); 4].map(|_| next())), [next(), next()])).collect();
        cases.push(([[0; 4], [u32::MAX; 4], [0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344], [1, 2, 3, 4]], [u32::MAX; 2]));
        for (counters, key) in cases {
            assert_eq!(philox4x32_10_x4(counters, key), counters.map(|c| philox4x32_10(c, key)), "{counters:x?} {key:x?}");
        }
        for kind in [Noise::Uniform, Noise::Gaussian] {
            for (seed, step, first) in [(5, 10, 0), (u64::MAX, 1 << 40, u32::MAX - 1), (12345, 7, 4093)] {
                let four = noise3_x4(seed, step, first, kind).map(|v| v.map(f64::to_bits));
                let one: [[u64; 3]; 4] = std::array::from_fn(|l| noise3(seed, step, first.wrapping_add(l as u32), kind).map(f64::to_bits));
                assert_eq!(four, one, "{kind:?} at ({seed}, {step}, {first})");
            }
        }
        #[cfg(target_arch = "x86_64")]
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("this CPU has no AVX2: only the scalar lanes are checked");
        }
    }

    #[test]
    fn block_layout() {
        let seed = 0x0123_4567_89ab_cdef_u64;
        let step = 0xfedc_ba98_7654_3210_u64;
        assert_eq!(block(seed, step, 7, 3), philox4x32_10([7, 3, 0x7654_3210, 0xfedc_ba98], [0x89ab_cdef, 0x0123_4567]));
    }

    /// Mean, variance, fourth moment and the largest |cross-correlation|.
    fn moments(kind: Noise) -> (f64, f64, f64, f64) {
        let draws = 100_000u32;
        let (mut s1, mut s2, mut s4) = (0.0, 0.0, 0.0);
        let mut cross = [0.0f64; 3];
        for id in 0..draws {
            let v = noise3(42, 1000 + (id as u64 % 7), id, kind);
            for x in v {
                s1 += x;
                s2 += x * x;
                s4 += x * x * x * x;
            }
            cross[0] += v[0] * v[1];
            cross[1] += v[1] * v[2];
            cross[2] += v[0] * v[2];
        }
        let m = 3.0 * draws as f64;
        let mean = s1 / m;
        let max_cross = cross.iter().map(|c| (c / draws as f64).abs()).fold(0.0, f64::max);
        (mean, s2 / m - mean * mean, s4 / m, max_cross)
    }

    #[test]
    fn uniform_noise_has_unit_variance() {
        let (mean, var, m4, cross) = moments(Noise::Uniform);
        // Standard errors over 3·10⁵ values: mean 0.0018, variance 0.0016.
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.01, "variance {var}");
        assert!((m4 - 1.8).abs() < 0.02, "fourth moment {m4} (uniform: 9/5)");
        assert!(cross < 0.015, "cross-correlation {cross}");
        for id in 0..1000 {
            for x in noise3(1, 2, id, Noise::Uniform) {
                assert!(x.abs() < 3f64.sqrt());
            }
        }
        assert_eq!(uniform_unit_variance(0), -uniform_unit_variance(u32::MAX));
    }

    #[test]
    fn gaussian_noise_is_standard_normal() {
        let (mean, var, m4, cross) = moments(Noise::Gaussian);
        // Standard errors over 3·10⁵ values: mean 0.0018, variance 0.0026, m4 0.018.
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.015, "variance {var}");
        assert!((m4 - 3.0).abs() < 0.1, "fourth moment {m4} (normal: 3)");
        assert!(cross < 0.015, "cross-correlation {cross}");
    }

    #[test]
    fn inputs_select_independent_streams_and_repeat_exactly() {
        for kind in [Noise::Uniform, Noise::Gaussian] {
            let base = noise3(5, 10, 3, kind);
            let bits = |v: [f64; 3]| v.map(f64::to_bits);
            assert_eq!(bits(base), bits(noise3(5, 10, 3, kind)));
            assert_ne!(base, noise3(5, 10, 4, kind), "id");
            assert_ne!(base, noise3(5, 11, 3, kind), "step");
            assert_ne!(base, noise3(6, 10, 3, kind), "seed");
            assert_ne!(base, noise3(5, 10 + (1 << 32), 3, kind), "high step word");
            assert_ne!(base, noise3(5 + (1 << 32), 10, 3, kind), "high seed word");
        }
        assert_ne!(noise3(5, 10, 3, Noise::Uniform), noise3(5, 10, 3, Noise::Gaussian));
        assert_eq!(Noise::default(), Noise::Uniform);
        assert_eq!(Noise::from_keyword("gaussian"), Some(Noise::Gaussian));
        assert_eq!(Noise::from_keyword("normal"), None);
    }

    #[test]
    fn open_unit_interval_excludes_the_ends() {
        assert!(open_unit_52(0, 0) > 0.0);
        assert!(open_unit_52(u32::MAX, u32::MAX) < 1.0);
        assert!(noise3(0, 0, 0, Noise::Gaussian).iter().all(|x| x.is_finite()));
    }
}
