//! Stress decay around a force dipole in a fibre network (seed 000,
//! checkpoint 6): `inputs/force_dipole.in` on diluted triangular lattices of
//! bending-stiff fibres (`cellmd build lattice --bending --dipole`, radius
//! 32 a, about 3700 nodes, clamped rim), a 2 pN contractile bond of length 2a at the centre,
//! relaxed at T = 0 by Newton steps.
//!
//! Oracle: in a 2D elastic continuum the stress of a force dipole decays as
//! r⁻² (the derivative of the 2D Kelvin solution, whose displacement falls
//! as 1/r); seed 000 accepts a log-log slope of |σ_xx(r)| in [−2.5, −1.5].
//! The per-node stress is LAMMPS' stress/atom (−W_i, `sxx` of the dump) over
//! the area per node √3a²/2, averaged in |·| over rings between 4a and R/2
//! (six rings, logarithmically spaced), the slope a least-squares fit of
//! ln⟨|σ_xx|⟩ against ln⟨r⟩. The full lattice without bending, an
//! isotropic elastic sheet, must give −2 within 0.1; the fibre network at
//! p = 0.8 (z ≈ 4.8, above the central-force threshold 3.96), the mean
//! profile of three seeds, seed 000's window.
//!
//! `cargo test --test suite force_dipole:: -- --nocapture` prints the profiles;
//! studies/force_dipole/ runs larger discs and more seeds.

use crate::common;

use cellmd::build::{Common, LatticeArgs};

const DECK: &str = "inputs/force_dipole.in";
const RADIUS: f64 = 32.0;

/// Ring-averaged |σ_xx| (pN/µm) against the ring's mean r (µm), and the
/// log-log slope, for one relaxed lattice.
fn profile(p: f64, bending: bool, seed: u64) -> (Vec<(f64, f64)>, f64) {
    let args = LatticeArgs {
        radius: RADIUS,
        spacing: 1.0,
        bond_probability: p,
        bending,
        dipole: true,
        common: Common { seed, output: "lattice.top".into(), rest_from_geometry: false },
        ..LatticeArgs::default()
    };
    let (mut sim, _) = common::run_deck_on_lattice(DECK, &args, &[]);
    let virial = sim.particle_virial().unwrap();
    let area = 3f64.sqrt() / 2.0;
    let (r_in, r_out, rings) = (4.0f64, RADIUS / 2.0, 6);
    let mut sums = vec![(0.0, 0.0, 0usize); rings];
    for (x, w) in sim.state.positions.iter().zip(&virial) {
        let r = x.truncate().length();
        if r < r_in || r >= r_out {
            continue;
        }
        let k = (((r / r_in).ln() / (r_out / r_in).ln()) * rings as f64) as usize;
        sums[k].0 += r;
        sums[k].1 += (w[0] / area).abs();
        sums[k].2 += 1;
    }
    let points: Vec<(f64, f64)> = sums.iter().map(|&(r, s, n)| (r / n as f64, s / n as f64)).collect();
    (points.clone(), slope(&points))
}

/// Least-squares slope of ln y against ln x.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (x, y): (Vec<f64>, Vec<f64>) = points.iter().map(|&(r, s)| (r.ln(), s.max(f64::MIN_POSITIVE).ln())).unzip();
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    x.iter().zip(&y).map(|(x, y)| (x - mx) * (y - my)).sum::<f64>() / x.iter().map(|x| (x - mx).powi(2)).sum::<f64>()
}

fn show(label: &str, (points, slope): &(Vec<(f64, f64)>, f64)) {
    let rows: Vec<String> = points.iter().map(|(r, s)| format!("{r:.2}:{s:.3e}")).collect();
    println!("{label}: slope {slope:.3}; r:|σ_xx| {}", rows.join(" "));
}

#[test]
fn dipole_stress_decays_as_r_to_the_minus_two_in_a_rigid_fibre_network() {
    let full = profile(1.0, false, 1);
    show("full lattice, no bending", &full);
    assert!((full.1 + 2.0).abs() < 0.1, "the isotropic elastic sheet decays with slope {}, not −2", full.1);

    let seeds = [1, 2, 3];
    let fibres: Vec<_> = seeds.iter().map(|&s| profile(0.8, true, s)).collect();
    for (s, f) in seeds.iter().zip(&fibres) {
        show(&format!("p = 0.8 fibres, seed {s}"), f);
    }
    let mean: Vec<(f64, f64)> = (0..fibres[0].0.len())
        .map(|k| {
            let n = fibres.len() as f64;
            (fibres.iter().map(|f| f.0[k].0).sum::<f64>() / n, fibres.iter().map(|f| f.0[k].1).sum::<f64>() / n)
        })
        .collect();
    let mean_slope = slope(&mean);
    println!("p = 0.8 fibres, mean profile of {} seeds: slope {mean_slope:.3}", seeds.len());
    assert!((-2.5..=-1.5).contains(&mean_slope), "fibre network slope {mean_slope} outside seed 000's [−2.5, −1.5]");
}
