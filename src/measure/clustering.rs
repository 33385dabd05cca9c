//! Fibre clustering between two cells (Ouyang et al. 2022): the ratio
//! S_max/S_min of the fibre density across the band that joins them, the
//! read-out the paper takes from its fluorescence images.
//!
//! # Definition
//!
//! For a bond type T (the fibres) and two groups A and B (two cells),
//! thermo `clustering/T/A/B`, in the xy plane:
//!
//! - a and b are the groups' centroids (unwrapped), û = (b − a)/|b − a| the
//!   axis between them and n̂ ⊥ û in the plane; r_A and r_B the largest
//!   distance of a member from its centroid (a ring's radius);
//! - the **region of interest** is the rectangle between the two cells,
//!   r_A ≤ (x − a)·û ≤ |b − a| − r_B along the axis and |(x − a)·n̂| ≤ W/2
//!   across it, with W = 1.5·(r_A + r_B): three cell radii, the paper's
//!   300 µm box across the band for cells of 200 µm diameter;
//! - the **profile**: the ROI cut across into 21 strips parallel to the axis,
//!   each holding the length of T bonds inside it (every bound bond clipped
//!   exactly to the strip: the fibre density, which the paper's
//!   fluorescence intensity stands for);
//! - S_max: the mean of the 7 strips centred on the densest one (shifted to
//!   stay inside the profile), S_min: the mean of the 3 outermost strips at
//!   each end (6 strips). The paper sums seven points around the maximum and
//!   seven from the two ends ("three or four values from each"); with 3 from
//!   each end here both are means, so a uniform density gives exactly 1.
//!
//! The ratio is 1 for a uniform network (up to the noise of a random one, of
//! which the maximum picks the upper side: a random network starts a little
//! above 1) and grows as fibres gather along the axis. It is infinite when
//! the outer strips are empty and NaN when the whole ROI is.

use glam::{DVec2, DVec3};

use crate::system::{Model, SimBox, State};

/// Strips across the region of interest.
pub const STRIPS: usize = 21;
/// Strips averaged around the maximum.
pub const PEAK: usize = 7;
/// Strips averaged at each end.
pub const END: usize = 3;
/// The ROI's width across the axis, in units of r_A + r_B.
pub const WIDTH: f64 = 1.5;

/// The centroid (xy, unwrapped) of `members` and the largest distance of one from it.
fn centre_and_radius(members: &[u32], state: &State, sim_box: &SimBox) -> (DVec2, f64) {
    let xy = |i: u32| sim_box.unwrap(state.positions[i as usize], state.images[i as usize]).truncate();
    let c = members.iter().map(|&i| xy(i)).sum::<DVec2>() / members.len() as f64;
    (c, members.iter().map(|&i| (xy(i) - c).length()).fold(0.0, f64::max))
}

/// The fraction [λ0, λ1] ⊂ [0, 1] of `v0 + λ·dv` within [lo, hi] (empty when λ0 ≥ λ1).
fn within(lo: f64, hi: f64, v0: f64, dv: f64, (l0, l1): (f64, f64)) -> (f64, f64) {
    if dv == 0.0 {
        return if v0 >= lo && v0 <= hi { (l0, l1) } else { (1.0, 0.0) };
    }
    let (a, b) = ((lo - v0) / dv, (hi - v0) / dv);
    (l0.max(a.min(b)), l1.min(a.max(b)))
}

/// The fibre length in each strip of the ROI between groups `a` and `b`.
pub fn profile(
    model: &Model,
    bound: Option<&[bool]>,
    state: &State,
    sim_box: &SimBox,
    bond_type: usize,
    a: &[u32],
    b: &[u32],
) -> [f64; STRIPS] {
    let ((ca, ra), (cb, rb)) = (centre_and_radius(a, state, sim_box), centre_and_radius(b, state, sim_box));
    let axis = cb - ca;
    let u = axis.normalize_or_zero();
    let n = u.perp();
    let (s_lo, s_hi) = (ra, axis.length() - rb);
    let half = WIDTH * (ra + rb) / 2.0;
    let strip = 2.0 * half / STRIPS as f64;
    let mut out = [0.0; STRIPS];
    if s_hi <= s_lo || half <= 0.0 {
        return out;
    }
    for (k, &[i, j]) in model.bonds.iter().enumerate() {
        if model.bond_type[k] as usize != bond_type || bound.is_some_and(|s| !s[k]) {
            continue;
        }
        let p = sim_box.unwrap(state.positions[i as usize], state.images[i as usize]);
        let d: DVec3 = sim_box.minimum_image(state.positions[j as usize] - state.positions[i as usize]);
        let (p, d) = (p.truncate() - ca, d.truncate());
        let length = d.length();
        let along = within(s_lo, s_hi, p.dot(u), d.dot(u), (0.0, 1.0));
        let (w0, dw) = (p.dot(n) + half, d.dot(n));
        for (m, slot) in out.iter_mut().enumerate() {
            let (l0, l1) = within(m as f64 * strip, (m + 1) as f64 * strip, w0, dw, along);
            if l1 > l0 {
                *slot += (l1 - l0) * length;
            }
        }
    }
    out
}

/// S_max/S_min of a profile (see the module documentation).
pub fn ratio(profile: &[f64; STRIPS]) -> f64 {
    let densest = (0..STRIPS).fold(0, |best, m| if profile[m] > profile[best] { m } else { best });
    let first = densest.saturating_sub(PEAK / 2).min(STRIPS - PEAK);
    let s_max = profile[first..first + PEAK].iter().sum::<f64>() / PEAK as f64;
    let s_min = (profile[..END].iter().sum::<f64>() + profile[STRIPS - END..].iter().sum::<f64>()) / (2 * END) as f64;
    s_max / s_min
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_strip_profile_sums_clipped_lengths_and_its_ratio() {
        // Uniform: 1. One strip doubled among 21: the 7 around it average (7 + 1)/7.
        let mut p = [2.0; STRIPS];
        assert_eq!(ratio(&p), 1.0);
        p[10] = 4.0;
        assert!((ratio(&p) - 8.0 / 7.0).abs() < 1e-15);
        // A maximum at the edge: the window shifts inside.
        let mut q = [1.0; STRIPS];
        q[0] = 8.0;
        assert!((ratio(&q) - (14.0 / 7.0) / (13.0 / 6.0)).abs() < 1e-15);
        // Clipping: a segment from −1 to 3 within [0, 2] keeps half.
        let (l0, l1) = within(0.0, 2.0, -1.0, 4.0, (0.0, 1.0));
        assert!((l0 - 0.25).abs() < 1e-15 && (l1 - 0.75).abs() < 1e-15);
        let (l0, l1) = within(0.0, 2.0, 3.0, 0.0, (0.0, 1.0));
        assert!(l0 >= l1);
    }
}
