//! Bond kinetics against exact results (issue: stateful bonds). Analytic
//! formulas here are test oracles only; the runtime decides every event per
//! bond from the force it carries.
//!
//! Most systems are pairs of `fixed` particles, so each bond's length — and
//! hence its force — is set by geometry alone and no noise enters.

use crate::common;

use crate::common::Case;

/// `n` pairs of fixed particles at separations `lengths[p % lengths.len()]`,
/// joined by bonds of type `b`.
fn fixed_pairs(n: usize, lengths: &[f64]) -> String {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for p in 0..n {
        let (x, y) = ((p % 300) as f64 * 3.0, (p / 300) as f64 * 3.0);
        let l = lengths[p % lengths.len()];
        top += &format!("{} a {x} {y} 0\n{} a {x} {y} {l}\n", 2 * p + 1, 2 * p + 2);
        bonds += &format!("b {} {}\n", 2 * p + 1, 2 * p + 2);
    }
    top + &bonds
}

/// For each length `lengths[g]`, one pair of fixed particles that far apart
/// joined by `per_length` parallel bonds of their own type `f{g}` (bonds listed
/// length by length): every bond of a pair carries the same tension, and a run
/// costs per bond, not per particle.
fn parallel_bonds(per_length: usize, lengths: &[f64]) -> String {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for (g, l) in lengths.iter().enumerate() {
        top += &format!("{} a {} 0 0\n{} a {} 0 {l}\n", 2 * g + 1, 3 * g, 2 * g + 2, 3 * g);
        bonds += &format!("f{g} {} {}\n", 2 * g + 1, 2 * g + 2).repeat(per_length);
    }
    top + &bonds
}

fn case(top: &str, bond_line: &str, deck_body: &str) -> Case {
    let ff = format!("particle a fixed\n{bond_line}\n");
    let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -10 1000 f y -10 1000 f z -10 1000 f\n{deck_body}");
    Case::new(&[("t.top", top), ("f.ff", &ff), ("deck.in", &deck)])
}

/// Rows of the CSV event log: (step, event, bond, force).
fn events(case: &Case) -> Vec<(u64, String, usize, f64)> {
    std::fs::read_to_string(case.path("events.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().unwrap(), f[2].to_string(), f[3].parse().unwrap(), f[7].parse().unwrap())
        })
        .collect()
}

/// Lifetimes at fixed force across a sweep: for each force F, 4·10⁴ parallel
/// bonds of their own type (harmonic, k = 10, held F/k beyond rest between
/// fixed particles) carrying the kinetic rule `rule`, run until the
/// longest-lived force has seen 20 mean lifetimes (a bond outlives that with
/// probability e^−20). The deck's lifetime table (`lifetimes`) must give, per
/// force, every bond broken at tension F, τ = 1/k(F) within 2 % (four standard
/// errors of an exponential mean), a standard error of τ/√N within 5 % (an
/// exponential's sd is its mean) and the censored estimate equal to τ; the break
/// steps must follow the exponential law (KS). Returns the measured τ(F).
fn lifetime_sweep(rule: &str, kt: f64, forces: &[f64], rate: impl Fn(f64) -> f64, rate_dt_max: f64, seed: u64) -> Vec<f64> {
    let k_bond = 10.0;
    let lengths: Vec<f64> = forces.iter().map(|f| 1.0 + f / k_bond).collect();
    let k_max = forces.iter().map(|&f| rate(f)).fold(0.0, f64::max);
    let k_min = forces.iter().map(|&f| rate(f)).fold(f64::INFINITY, f64::min);
    let dt = rate_dt_max / k_max;
    let steps = (20.0 / (k_min * dt)).ceil() as u64;
    let per_force = 40_000;
    let bond_lines: Vec<String> = (0..forces.len()).map(|g| format!("bond f{g} harmonic k {k_bond} r0 1 kinetics {rule}")).collect();
    let c = case(
        &parallel_bonds(per_force, &lengths),
        &bond_lines.join("\n"),
        &format!("temperature {kt}\ntimestep {dt}\nseed {seed}\nevents events.csv\nlifetimes lifetimes.csv\nrun {steps}\n"),
    );
    let sim = c.run();
    assert_eq!(sim.kinetics.engine.breaks as usize, per_force * forces.len(), "some bonds never broke");
    let table = std::fs::read_to_string(c.path("lifetimes.csv")).unwrap();
    let mut rows = table.lines();
    assert_eq!(rows.next(), Some("type,breaks,surviving,force[ε/σ],tau[τ],stderr[τ],tau_censored[τ]"));
    let mut measured = Vec::new();
    for (g, &f) in forces.iter().enumerate() {
        let row: Vec<&str> = rows.next().expect("a row per bond type").split(',').collect();
        let num = |k: usize| row[k].parse::<f64>().unwrap();
        assert_eq!((row[0], row[1], row[2]), (format!("f{g}").as_str(), per_force.to_string().as_str(), "0"));
        assert!((num(3) - f).abs() <= 1e-9 * f.max(1.0), "F = {f}: bonds broke at {}", num(3));
        let (tau, exact) = (num(4), 1.0 / rate(f));
        println!("F = {f:.4}: tau {tau:.5}, exact {exact:.5}, error {:+.3} %", 100.0 * (tau / exact - 1.0));
        assert!((tau / exact - 1.0).abs() < 0.02, "F = {f}: mean lifetime {tau}, exact {exact}");
        assert!((num(5) * (per_force as f64).sqrt() / tau - 1.0).abs() < 0.05, "F = {f}: stderr {} for tau {tau}", num(5));
        assert_eq!(num(6), tau, "no survivors: the censored estimate is the plain mean");
        measured.push(tau);
    }
    let mut steps_of: Vec<Vec<u64>> = vec![Vec::new(); forces.len()];
    for (step, kind, bond, _) in events(&c) {
        assert_eq!(kind, "break");
        steps_of[bond / per_force].push(step);
    }
    for (g, &f) in forces.iter().enumerate() {
        let ks = common::ks_exponential_steps(&steps_of[g], rate(f) * dt, None);
        assert!(ks < 1.95, "F = {f}: lifetimes not exponential, KS D√N = {ks}");
    }
    measured
}

/// Bell slip bonds: τ(F) = 1/(k0·exp(F·xβ/kT)) from 0 to 1.5 Fβ (a rate
/// ratio of e³; to 2 Fβ, e⁴, the run to 20 lifetimes of the slowest force
/// took 2.7 times as long: 38 s in release, for CI time).
#[test]
fn slip_lifetimes_follow_the_bell_law() {
    let (k0, x_beta, kt): (f64, f64, f64) = (1.0, 0.5, 1.0);
    let f_beta = kt / x_beta;
    let forces: Vec<f64> = [0.0, 0.5, 1.0, 1.5].iter().map(|a| a * f_beta).collect();
    lifetime_sweep(&format!("slip k0 {k0} x_beta {x_beta}"), kt, &forces, |f| k0 * (f * x_beta / kt).exp(), 0.05, 19);
}

/// Catch-slip bonds across a sweep spanning the lifetime maximum: τ = 1/k(F)
/// and the longest-lived force is F* = kT·ln(kc0·xc/(ks0·xs))/(xc + xs).
#[test]
fn catch_slip_lifetimes_follow_the_two_pathway_law() {
    let (kc0, xc, ks0, xs): (f64, f64, f64, f64) = (1.0, 1.0, 0.01, 0.5);
    let kt = 1.0;
    let f_star: f64 = kt * (kc0 * xc / (ks0 * xs)).ln() / (xc + xs);
    let fractions = [0.5, 0.75, 1.0, 1.25, 1.5];
    let forces: Vec<f64> = fractions.iter().map(|a| a * f_star).collect();
    let rate = |f: f64| kc0 * (-f * xc / kt).exp() + ks0 * (f * xs / kt).exp();
    let measured = lifetime_sweep(&format!("catch_slip kc0 {kc0} xc {xc} ks0 {ks0} xs {xs}"), kt, &forces, rate, 0.05, 17);
    // The longest-lived force of the sweep is F*, and lifetimes fall on both sides.
    let best = (0..forces.len()).max_by(|&a, &b| measured[a].total_cmp(&measured[b])).unwrap();
    assert_eq!(fractions[best], 1.0, "longest lifetime at {} F*, lifetimes {measured:?}", fractions[best]);
}

/// Cadherin sliding–rebinding catch bonds at fixed force, across a sweep
/// spanning the catch maximum: the mean lifetime matches the exact mean
/// first-passage time from B1 to U of the three-state chain (B1 ⇄ B2, both →
/// U), computed here by solving its generator, within 2 % with 4·10⁴ bonds per
/// force (2 % is four standard errors of an exponential mean); it rises with
/// force up to the maximum (catch) and falls beyond it (slip).
///
/// The runtime gives a bond the single effective rate k_eff = 1/MFPT (it does
/// not track B1 and B2), so its lifetimes at fixed force are exponential with
/// the exact mean (checked below), whereas the chain's own lifetime is a
/// mixture of two exponentials: its squared coefficient of variation reaches
/// 1.32 here (1 for an exponential). The mean is what the rule reproduces.
#[test]
fn cadherin_lifetimes_follow_the_sliding_rebinding_chain() {
    // k10 x1 ks0 xs kr0 xr k20 x2, with kT = 1.
    let p: [f64; 8] = [1.0, 0.2, 1.0, 1.0, 5.0, 1.0, 0.1, 0.3];
    let kt = 1.0;
    // Oracle: the transient generator on (B1, B2) is Q = [[−(k1+ks), ks], [kr, −(kr+k2)]];
    // mean absorption times solve Q·τ = −1 (Cramer's rule); the lifetime is τ_B1.
    let mfpt = |f: f64| {
        let bell = |k0: f64, x: f64| k0 * (f * x / kt).exp();
        let (k1, ks, kr, k2) = (bell(p[0], p[1]), bell(p[2], p[3]), bell(p[4], -p[5]), bell(p[6], p[7]));
        let (a, b, c, d) = (-(k1 + ks), ks, kr, -(kr + k2));
        (-d + b) / (a * d - b * c)
    };
    // The force of the longest lifetime, on a fine grid.
    let f_max = (0..=10_000).map(|k| k as f64 * 1e-3).max_by(|a, b| mfpt(*a).total_cmp(&mfpt(*b))).unwrap();
    let fractions = [0.0, 0.4, 0.7, 1.0, 1.6, 2.5];
    let forces: Vec<f64> = fractions.iter().map(|a| a * f_max).collect();
    let rule = format!("cadherin k10 {} x1 {} ks0 {} xs {} kr0 {} xr {} k20 {} x2 {}", p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]);
    // k·dt ≤ 0.08: the lifetime estimate is biased by (k·dt)²/12 ≤ 6e-4.
    let measured = lifetime_sweep(&rule, kt, &forces, |f| 1.0 / mfpt(f), 0.08, 23);
    // Catch below the maximum (each force lives longer than the one before),
    // slip beyond it: the longest-lived force of the sweep is F_max.
    for g in 1..forces.len() {
        let rising = fractions[g] <= 1.0;
        assert_eq!(measured[g] > measured[g - 1], rising, "lifetimes {measured:?} at {fractions:?} F_max");
    }
}

/// Constant loading rate r: slip bonds rupture most probably at
/// F* = Fβ·ln(r/(k0·Fβ)), and the rupture forces follow the Bell–Evans law
/// p(F) = (k(F)/r)·exp(−∫₀^F k/r).
///
/// The load ramps because a `motor` rule with an unreachable stall force
/// shortens each bond's rest length at constant speed v0 between fixed
/// ends: F(t) = k_bond·v0·t.
#[test]
fn slip_bonds_under_a_force_ramp_rupture_at_the_bell_evans_force() {
    let (k0, x_beta, kt): (f64, f64, f64) = (1.0, 1.0, 1.0);
    let f_beta = kt / x_beta;
    let (k_bond, v0): (f64, f64) = (100.0, 1.0);
    let r = k_bond * v0;
    let f_star = f_beta * (r / (k0 * f_beta)).ln();
    let dt = 2e-5;
    let n = 20_000;
    let steps = ((f_star + 6.0 * f_beta) / (r * dt)) as u64;
    let bond = format!("bond b harmonic k {k_bond} r0 1 kinetics motor v0 {v0} fs 1e12 kinetics slip k0 {k0} x_beta {x_beta}");
    let c = case(&fixed_pairs(n, &[1.0]), &bond, &format!("temperature {kt}\ntimestep {dt}\nseed 5\nevents events.csv\nrun {steps}\n"));
    let sim = c.run();
    assert_eq!(sim.kinetics.engine.breaks as usize, n);
    let mut forces: Vec<f64> = events(&c).iter().map(|e| e.3).collect();
    forces.sort_by(f64::total_cmp);
    // Kolmogorov–Smirnov against the exact CDF 1 − exp(−(k0/r)(e^(F/Fβ) − 1)·Fβ).
    let cdf = |f: f64| 1.0 - (-(k0 * f_beta / r) * ((f / f_beta).exp() - 1.0)).exp();
    let nn = n as f64;
    let d = forces
        .iter()
        .enumerate()
        .map(|(i, &f)| ((i + 1) as f64 / nn - cdf(f)).abs().max((i as f64 / nn - cdf(f)).abs()))
        .fold(0.0, f64::max);
    // The force is known only to within one step's increment r·dt = 0.002 Fβ.
    assert!(d * nn.sqrt() < 1.95, "rupture forces do not follow Bell–Evans: KS D√N = {}", d * nn.sqrt());
    // Most probable force: the peak of a Gaussian kernel density estimate.
    let h = 0.1 * f_beta;
    let density = |f: f64| forces.iter().map(|&x| (-(x - f).powi(2) / (2.0 * h * h)).exp()).sum::<f64>();
    let mode = (0..=400).map(|k| f_star - 2.0 + k as f64 * 0.01).max_by(|a, b| density(*a).total_cmp(&density(*b))).unwrap();
    assert!((mode - f_star).abs() < 0.1 * f_beta, "most probable rupture force {mode}, F* = {f_star}");
}

/// Rebinding at k_on and unbinding at k_off reach the bound fraction
/// k_on/(k_on + k_off); per step the chain is exactly two-state with
/// probabilities a = 1 − e^(−k_off·dt) and b = 1 − e^(−k_on·dt), stationary b/(a + b).
#[test]
fn binding_and_unbinding_reach_the_steady_state_fraction() {
    let (k_on, k_off, dt): (f64, f64, f64) = (2.0, 3.0, 0.002);
    let n = 10_000;
    let bond = format!("bond b harmonic k 1 r0 1 kinetics slip k0 {k_off} x_beta 0 kinetics rebind k_on {k_on} capture 2");
    let relax = (1.0 / ((k_on + k_off) * dt)) as u64; // one correlation time in steps
    let c = case(
        &fixed_pairs(n, &[1.0]),
        &bond,
        &format!("temperature 1\ntimestep {dt}\nseed 9\nthermo {relax} step nbound/b\nthermo_file t.csv\nrun {}\n", 60 * relax),
    );
    c.run();
    let rows: Vec<f64> =
        std::fs::read_to_string(c.path("t.csv")).unwrap().lines().skip(1).map(|l| l.split(',').nth(1).unwrap().parse().unwrap()).collect();
    // Skip 10 correlation times, then average samples one correlation time apart.
    let samples = &rows[10..];
    let fraction = samples.iter().sum::<f64>() / (samples.len() as f64 * n as f64);
    let (a, b): (f64, f64) = (-(-k_off * dt).exp_m1(), -(-k_on * dt).exp_m1());
    let discrete = b / (a + b);
    let continuous = k_on / (k_on + k_off);
    // Binomial error of one sample, samples correlated by e^(−1): inflate by √((1+e⁻¹)/(1−e⁻¹)).
    let e1 = (-1.0f64).exp();
    let error = (discrete * (1.0 - discrete) / n as f64).sqrt() * ((1.0 + e1) / (1.0 - e1)).sqrt() / (samples.len() as f64).sqrt();
    assert!((fraction - discrete).abs() < 4.0 * error, "bound fraction {fraction}, expected {discrete} ± {error}");
    assert!((discrete - continuous).abs() < 1e-3, "the time step biases the steady state: {discrete} vs {continuous}");
}

/// Equal-load-sharing fibre bundle with thresholds uniform on [0, 1]: the
/// load per fibre k·ε·(1 − ε) peaks at 1/4 at strain 1/2 (Daniels).
#[test]
fn fibre_bundle_with_uniform_thresholds_peaks_at_a_quarter() {
    let n = 20_000;
    // Strain grows as the rest length shrinks at v0 between fixed ends 1 apart.
    let (v0, dt) = (0.5, 2e-4);
    let bond = format!("bond b spring k 1 r0 1 kinetics threshold strain 0.5 spread 2 kinetics motor v0 {v0} fs 1e12");
    let steps = (0.45 / (v0 * dt)) as u64; // r0 from 1 to 0.55: strain up to 0.82
    let c = case(
        &fixed_pairs(n, &[1.0]),
        &bond,
        &format!("timestep {dt}\nthermo 10 step nbound/b tension/b\nthermo_file t.csv\nrun {steps}\n"),
    );
    c.run();
    let (mut peak_load, mut peak_strain) = (0.0, 0.0);
    for line in std::fs::read_to_string(c.path("t.csv")).unwrap().lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let (bound, tension) = (v[1], v[2]);
        let load = tension / n as f64;
        if load > peak_load && bound > 0.0 {
            // Every intact fibre carries k·ε: the strain is tension/bound.
            (peak_load, peak_strain) = (load, tension / bound);
        }
    }
    // Finite-N fluctuations of the surviving fraction are ~0.5/√N ≈ 0.004.
    assert!((peak_load - 0.25).abs() < 0.01, "peak load per fibre {peak_load}");
    assert!((peak_strain - 0.5).abs() < 0.03, "strain at peak {peak_strain}");
}

/// Reads the bond state saved by `write_state`.
fn saved_bonds(case: &Case, file: &str) -> (cellmd::system::State, cellmd::system::BondState) {
    let state = cellmd::output::restart::read_state(&case.path(file)).unwrap().to_state();
    let bonds = state.bonds.clone().unwrap();
    (state, bonds)
}

/// A motor pulling a free bead against a load f: the motor's law is linear
/// in the tension F it carries, v = v0·(1 − F/Fs), stalling at Fs. The
/// moving cargo adds its drag, F = f + γ·v, so the bead walks at
/// v = v0·(1 − f/Fs)/(1 + γ·v0/Fs) below stall and stands still beyond it.
/// Beads anchored by motor bonds, each pulled away by its own force, kT = 0.
#[test]
fn motor_force_velocity_is_linear_to_stall() {
    let (v0, fs, k, gamma): (f64, f64, f64, f64) = (0.5, 2.0, 200.0, 1.0);
    let loads = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5];
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    let mut deck = String::from("timestep 1e-4\n");
    for (m, f) in loads.iter().enumerate() {
        let x = 10.0 * m as f64;
        // Start at the loaded length so the bond already carries f.
        top += &format!("{} a {x} 0 0\n{} bead {x} 0 {}\n", 2 * m + 1, 2 * m + 2, 5.0 + f / k);
        bonds += &format!("b {} {}\n", 2 * m + 1, 2 * m + 2);
        deck += &format!("group g{m} id {}\nexternal pull{m} g{m} constant_force fz {f}\n", 2 * m + 2);
    }
    deck += "run 2000\nwrite_state a.state\nrun 10000\nwrite_state b.state\n";
    let ff = format!("particle a fixed\nparticle bead drag {gamma}\nbond b harmonic k {k} r0 5 kinetics motor v0 {v0} fs {fs}\n");
    let full = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -10 100 f y -10 10 f z -10 10 f\n{deck}");
    let c = Case::new(&[("t.top", &(top + &bonds)), ("f.ff", &ff), ("deck.in", &full)]);
    c.run();
    let (a, _) = saved_bonds(&c, "a.state");
    let (b, _) = saved_bonds(&c, "b.state");
    let elapsed = b.time - a.time;
    for (m, f) in loads.iter().enumerate() {
        let v = (b.positions[2 * m + 1].z - a.positions[2 * m + 1].z) / elapsed;
        let expected = -v0 * (1.0 - f / fs).max(0.0) / (1.0 + gamma * v0 / fs);
        assert!((v - expected).abs() < 1e-9 * v0, "load {f}: bead velocity {v}, expected {expected}");
    }
}

/// A ratchet's rest length grows at v0·exp(−f·δ/kT) against the compressive
/// load f its bond carries: between fixed ends the load rises as it grows,
/// and f(t) = k·y with y(t) = ln(e^(a·y0) + a·v0·t)/a, a = k·δ/kT.
#[test]
fn ratchet_growth_slows_exponentially_with_load() {
    let (v0, delta, kt, k) = (1.0, 0.05, 1.0, 20.0);
    let a = k * delta / kt;
    let compressions = [0.0, 0.5, 1.0, 2.0];
    // Fixed ends at 3 − y0 with rest length 3: compression y0, load k·y0.
    let lengths: Vec<f64> = compressions.iter().map(|y| 3.0 - y).collect();
    let dt = 1e-4;
    let bond = format!("bond b harmonic k {k} r0 3 kinetics ratchet v0 {v0} delta {delta}");
    let c = case(
        &fixed_pairs(compressions.len(), &lengths),
        &bond,
        &format!("temperature {kt}\ntimestep {dt}\nrun 1\nwrite_state one.state\nrun 9999\nwrite_state end.state\n"),
    );
    c.run();
    let (_, one) = saved_bonds(&c, "one.state");
    let (end_state, end) = saved_bonds(&c, "end.state");
    for (m, &y0) in compressions.iter().enumerate() {
        // One step: the growth rate at the initial load.
        let v = (one.rest[m].unwrap() - 3.0) / dt;
        let expected = v0 * (-k * y0 * delta / kt).exp();
        // Δr0 = (3 + v·dt) − 3 cancels digits: its round-off is ≤ 2ε·3/(v·dt).
        let roundoff = 2.0 * f64::EPSILON * 3.0 / (expected * dt);
        assert!((v / expected - 1.0).abs() < roundoff, "load {}: growth {v}, expected {expected}", k * y0);
        // After t = 1: the exact solution of dy/dt = v0·e^(−a·y), to O(dt).
        let t = end_state.time;
        let y = end.rest[m].unwrap() - lengths[m];
        let exact = ((a * y0).exp() + a * v0 * t).ln() / a;
        assert!((y - exact).abs() < 1e-3 * exact.max(1.0), "y0 = {y0}: compression {y} at t = {t}, exact {exact}");
    }
}

/// Plastic reset under a constant pull: between resets the extension x
/// relaxes as x' = (F − k·x)/γ, and a reset (L0 ← L) happens when x
/// reaches s·L0, so the n-th interval lasts −(γ/k)·ln(1 − k·s·L0ₙ/F) with
/// L0ₙ₊₁ = (1 + s)·L0ₙ. Returns the reset times of a bond that starts at
/// rest at L0₀ = `start`: the type's r0 = 1, or the bond's own r0 (`own`,
/// the topology's fourth field) with the type's r0 left at 1.
fn plastic_resets(start: f64, own: bool) -> (Vec<f64>, Vec<f64>) {
    let (k, gamma, f, s, dt): (f64, f64, f64, f64, f64) = (1.0, 1.0, 1.0, 0.2, 1e-5);
    let rest = if own { format!(" {start:?}") } else { String::new() };
    let top = format!("[ particles ]\n1 a 0 0 0\n2 bead 0 0 {start:?}\n[ bonds ]\nb 1 2{rest}\n");
    let ff = format!("particle a fixed\nparticle bead drag {gamma}\nbond b harmonic k {k} r0 1 kinetics plastic threshold {s}\n");
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 100 f\ntimestep {dt}\ngroup bead id 2\n\
         external pull bead constant_force fz {f}\nevents events.csv\nrun 200000\n"
    );
    let c = Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)]);
    c.run();
    let resets: Vec<f64> = events(&c).iter().filter(|e| e.1 == "reset").map(|e| e.0 as f64 * dt).collect();
    let (mut t, mut l0, mut exact) = (0.0, start, Vec::new());
    while exact.len() < resets.len().max(5) && k * s * l0 < f {
        t += -(gamma / k) * (1.0 - k * s * l0 / f).ln();
        l0 *= 1.0 + s;
        exact.push(t);
    }
    (resets, exact)
}

#[test]
fn plastic_resets_follow_the_exact_time_course() {
    let dt = 1e-5;
    let mut first = Vec::new();
    for (start, own) in [(1.0, false), (0.7, true)] {
        let (resets, exact) = plastic_resets(start, own);
        first.push(resets[0]);
        assert!(resets.len() >= 5, "L0 = {start}: only {} resets", resets.len());
        for (n, (&measured, &t)) in resets.iter().zip(&exact).take(5).enumerate() {
            // Euler error O(dt) per interval plus the one-step lag of a reset.
            assert!((measured - t).abs() < 10.0 * dt * (n + 1) as f64, "L0 = {start}: reset {n} at t = {measured}, exact {t}");
        }
        println!("plastic from L0 = {start} (own r0: {own}): resets at {:?}, exact {:?}", &resets[..5], &exact[..5]);
    }
    // The bond's own r0 is what the course starts from: from the type's r0 the first reset comes 0.07 later.
    assert!((first[0] - first[1]).abs() > 0.05, "first resets {first:?}");
}

/// Maturation: a bond's energy is E_full·(1 − exp(−age/τ)) at every step.
#[test]
fn maturation_follows_its_exact_time_course() {
    let (k, tau, dt) = (4.0, 0.05, 1e-3);
    let bond = format!("bond b harmonic k {k} r0 1 kinetics maturation tau {tau}");
    let c = case(&fixed_pairs(3, &[1.5]), &bond, &format!("timestep {dt}\nthermo 10 step pe/harmonic\nthermo_file t.csv\nrun 200\n"));
    c.run();
    let full = 3.0 * 0.5 * k * 0.25;
    for line in std::fs::read_to_string(c.path("t.csv")).unwrap().lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let expected = full * (1.0 - (-v[0] * dt / tau).exp());
        assert!((v[1] - expected).abs() <= 1e-12 * full, "step {}: E = {}, expected {expected}", v[0], v[1]);
    }
}

/// Kinetics (unbinding, rebinding, motors) with thermal noise: the same bits
/// on one and two threads, events included.
#[test]
fn kinetics_runs_are_bit_identical_across_thread_counts() {
    let (top, ff) = common::kinetic_sites();
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 45 f y -5 35 f z -5 5 f\nneighbor skin 0.2\ntemperature 1\ntimestep 2e-4\nseed 3\nevents events.csv\nrun 3000\n";
    let run = |threads: usize| {
        let c = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
        let sim = c.run_with_threads(threads);
        let log = std::fs::read(c.path("events.csv")).unwrap();
        (common::position_bits(&sim), sim.state.bonds.clone().unwrap(), log, sim.kinetics.engine.breaks, sim.kinetics.engine.forms)
    };
    let (one, two) = (run(1), run(2));
    assert!(one.3 > 100, "too few events to test: {}", one.3);
    assert!(one.4 > 100, "too few bonds formed to test: {}", one.4);
    assert_eq!(one.0, two.0);
    assert_eq!(one.1, two.1);
    assert_eq!(one.2, two.2);
}

/// Pairs of fixed sites that meet within the capture radius form bonds at
/// k_on; formed bonds unbind at k_off and the same pair binds again through
/// the same bond: the bound fraction reaches k_on/(k_on + k_off), and the
/// bond list holds one bond per pair however often it rebinds.
#[test]
fn bond_formation_reaches_the_steady_state_and_reuses_bonds() {
    let (k_on, k_off, dt): (f64, f64, f64) = (2.0, 3.0, 0.002);
    // 2 000 pairs for CI time (5 000 took 64 s of the test binary's 124 s); the
    // tolerance below follows n.
    let n = 2_000;
    let mut top = String::from("[ particles ]\n");
    for p in 0..n {
        let (x, y) = ((p % 100) as f64 * 3.0, (p / 100) as f64 * 3.0);
        top += &format!("{} a {x} {y} 0\n{} b {x} {y} 0.5\n", 2 * p + 1, 2 * p + 2);
    }
    let ff = format!(
        "particle a fixed\nparticle b fixed\nbond link harmonic k 1 r0 0.5 kinetics slip k0 {k_off} x_beta 0\nbind a b link k_on {k_on} capture 1\n"
    );
    let relax = (1.0 / ((k_on + k_off) * dt)) as u64;
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x -1 301 f y -1 151 f z -1 1 f\ntemperature 1\ntimestep {dt}\nseed 21\n\
         thermo {relax} step nbound/link\nthermo_file t.csv\nrun {}\n",
        60 * relax
    );
    let c = Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)]);
    let sim = c.run();
    assert_eq!(sim.model.bonds.len(), n, "one bond per pair, reused");
    assert_eq!(sim.kinetics.engine.forms as usize, n);
    assert!(sim.kinetics.engine.rebinds > 10 * n as u64);
    let rows: Vec<f64> =
        std::fs::read_to_string(c.path("t.csv")).unwrap().lines().skip(1).map(|l| l.split(',').nth(1).unwrap().parse().unwrap()).collect();
    let samples = &rows[10..];
    let fraction = samples.iter().sum::<f64>() / (samples.len() as f64 * n as f64);
    // Within a step unbinding is decided before binding, so the discrete
    // chain's stationary fraction differs from the continuous
    // k_on/(k_on + k_off) by O((k_on + k_off)·dt): allow the statistical
    // error plus that bias bound.
    let continuous = k_on / (k_on + k_off);
    let e1 = (-1.0f64).exp();
    let error = (continuous * (1.0 - continuous) / n as f64).sqrt() * ((1.0 + e1) / (1.0 - e1)).sqrt() / (samples.len() as f64).sqrt();
    let bias = (k_on + k_off) * dt;
    assert!((fraction - continuous).abs() < 4.0 * error + bias * continuous, "bound fraction {fraction}, expected {continuous} ± {error}");
}

/// No particle exceeds `max_bonds`, and the capacity fills when binding is fast.
#[test]
fn bond_formation_respects_max_bonds() {
    // Hubs with 6 partners each within capture; a hub takes at most 2.
    let mut top = String::from("[ particles ]\n");
    let mut id = 1;
    for h in 0..200 {
        let (x, y) = ((h % 20) as f64 * 5.0, (h / 20) as f64 * 5.0);
        top += &format!("{id} hub {x} {y} 0\n");
        id += 1;
        for k in 0..6 {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            top += &format!("{id} leg {} {} 0\n", x + 0.5 * a.cos(), y + 0.5 * a.sin());
            id += 1;
        }
    }
    let ff = "particle hub fixed\nparticle leg fixed\nbond link harmonic k 1 r0 0.5\nbind hub leg link k_on 100 capture 0.6 max_bonds 2\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -2 100 f y -2 50 f z -1 1 f\ntimestep 0.01\nseed 2\nrun 50\n";
    let c = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    let sim = c.run();
    let mut per_particle = vec![0; sim.model.len()];
    for &[i, j] in &sim.model.bonds {
        per_particle[i as usize] += 1;
        per_particle[j as usize] += 1;
    }
    for (p, &n) in per_particle.iter().enumerate() {
        let limit = if sim.model.type_names[sim.model.types[p] as usize] == "hub" { 2 } else { 1 };
        assert!(n <= limit, "particle {} has {n} bonds", sim.model.ids[p]);
    }
    assert_eq!(sim.model.bonds.len(), 2 * 200, "every hub reached its capacity");
}

/// A run with bond formation split by a restart is bit-identical to an
/// uninterrupted one: formed bonds are part of the restart.
#[test]
fn restart_resumes_formed_bonds_bit_identically() {
    let mut top = String::from("[ particles ]\n");
    for p in 0..400 {
        let (x, y) = ((p % 20) as f64 * 1.2, (p / 20) as f64 * 1.2);
        top += &format!("{} s {x} {y} 0\n", p + 1);
    }
    let ff = "particle s drag 1\nbond link harmonic k 5 r0 0.8 kinetics slip k0 1 x_beta 0.2\nbind s s link k_on 5 capture 1.3 max_bonds 3\npair s s soft_repulsion k 20 sigma 0.6\n";
    // z leaves room for the thermal motion out of the plane: a particle
    // leaving a fixed box stops a run (lost atoms).
    let deck = |body: &str| {
        format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -2 26 p y -2 26 p z -10 10 f\nneighbor skin 0.3\ntemperature 0.2\ntimestep 2e-3\nseed 8\n{body}")
    };
    let run = |body: &str, copy_from: Option<&Case>| {
        let c = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck(body))]);
        if let Some(src) = copy_from {
            std::fs::copy(src.path("half.state"), c.path("half.state")).unwrap();
        }
        let sim = c.run();
        (c, sim)
    };
    let (_, whole) = run("run 400\nrun 400\n", None);
    let (first, _) = run("run 400\nwrite_state half.state\n", None);
    let (_, resumed) = run("read_state half.state\nrun 400\n", Some(&first));
    assert!(whole.kinetics.engine.forms > 50, "too few bonds formed: {}", whole.kinetics.engine.forms);
    assert_eq!(whole.model.bonds, resumed.model.bonds);
    assert_eq!(whole.state.bonds, resumed.state.bonds);
    let bits = |s: &cellmd::run::Simulation| s.state.positions.iter().map(|x| x.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&whole), bits(&resumed));
}

/// `partner nearest` binds mutual-nearest pairs only; `partner random`
/// (the default) accepts candidates in (i, j) order. Triples at 0, 0.6 and
/// 0.9 with certain binding: nearest bonds the last two (0.3 apart), random
/// bonds the first pair it meets.
#[test]
fn bond_formation_partner_modes() {
    let mut top = String::from("[ particles ]\n");
    for t in 0..100 {
        let y = 3.0 * t as f64;
        top += &format!("{} s 0 {y} 0\n{} s 0.6 {y} 0\n{} s 0.9 {y} 0\n", 3 * t + 1, 3 * t + 2, 3 * t + 3);
    }
    for (mode, expected) in [("nearest", [2u32, 3]), ("random", [1, 2])] {
        let ff = format!("particle s fixed\nbond link harmonic k 1 r0 0.5\nbind s s link k_on 1e9 capture 1 partner {mode}\n");
        let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -1 2 f y -1 301 f z -1 1 f\ntimestep 1\nrun 1\n";
        let c = Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", deck)]);
        let sim = c.run();
        assert_eq!(sim.model.bonds.len(), 100, "{mode}: one bond per triple");
        for &[i, j] in &sim.model.bonds {
            let (a, b) = (sim.model.ids[i as usize], sim.model.ids[j as usize]);
            let base = 3 * ((a - 1) / 3) as u32;
            assert_eq!([a as u32 - base, b as u32 - base], expected, "{mode}: bond {a}-{b}");
        }
    }
}

/// The MCAP trajectory's `/cellmd/events` channel carries exactly the events
/// of the CSV log (same steps, kinds, bonds, particles, forces and ages, bit
/// for bit), and each event message is followed by the bond state it left.
#[test]
fn mcap_event_channel_carries_the_event_log() {
    let bond = "bond f0 harmonic k 10 r0 1 kinetics slip k0 2 x_beta 0.2 kinetics rebind k_on 3 capture 2";
    let c = case(
        &parallel_bonds(300, &[1.2]),
        bond,
        "temperature 1\ntimestep 0.01\nseed 8\nevents events.csv\ndump t every 100 mcap t.mcap\nrun 400\n",
    );
    c.run();
    let csv = std::fs::read_to_string(c.path("events.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv.lines().skip(1).map(|l| l.split(',').map(String::from).collect()).collect();
    assert!(rows.len() > 200, "too few events to test: {}", rows.len());
    let bytes = std::fs::read(c.path("t.mcap")).unwrap();
    let (mut from_mcap, mut states_after_events) = (Vec::new(), 0);
    let mut last_topic = String::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        let topic = message.channel.topic.clone();
        if topic == "/cellmd/bond_state" && last_topic == "/cellmd/events" {
            states_after_events += 1;
        }
        if topic == "/cellmd/events" {
            let doc = cellmd::output::mcap_messages::message_json(&message).unwrap();
            for e in doc["events"].as_array().unwrap() {
                assert_eq!(e["step"], doc["step"]);
                from_mcap.push(e.clone());
            }
        }
        last_topic = topic;
    }
    assert_eq!(from_mcap.len(), rows.len());
    for (e, row) in from_mcap.iter().zip(&rows) {
        let number = |k: usize| row[k].parse::<f64>().unwrap();
        assert_eq!(e["step"].as_u64().unwrap(), row[0].parse::<u64>().unwrap());
        assert_eq!(e["kind"].as_str().unwrap(), row[2]);
        assert_eq!(e["bond"].as_u64().unwrap(), row[3].parse::<u64>().unwrap());
        assert_eq!(e["particles"], serde_json::json!([row[5].parse::<u64>().unwrap(), row[6].parse::<u64>().unwrap()]));
        assert_eq!(e["force"].as_f64().unwrap().to_bits(), number(7).to_bits());
        assert_eq!(e["age"].as_f64().unwrap().to_bits(), number(9).to_bits());
    }
    let event_steps = rows.iter().map(|r| &r[0]).collect::<std::collections::BTreeSet<_>>().len();
    assert_eq!(states_after_events, event_steps, "one bond-state message after each step's events");
}

/// Clutch traction: a filament held on the substrate by clutch bonds and
/// pulled along them with force f per bead settles where the clutches carry the
/// whole load, so `tension/clutch` = N·f (the bonds lie along the pull, so
/// their summed tension is the traction on the substrate). The clutches bind to
/// fixed sites, or to movable ligands (drag 1) each tethered to a fixed pin,
/// whose tethers then carry the same traction.
#[test]
fn clutch_traction_balances_the_pulling_force() {
    let n = 8;
    let f = 0.7;
    for movable in [false, true] {
        let mut top = String::from("[ particles ]\n");
        let mut bonds = String::from("[ bonds ]\n");
        for k in 0..n {
            let (bead, site, pin) = (3 * k + 1, 3 * k + 2, 3 * k + 3);
            let x = 0.5 * k as f64;
            top += &format!("{bead} actin {x} 0 0\n{site} site {} 0 0\n{pin} pin {} 0 0\n", x - 0.05, x - 0.1);
            bonds += &format!("clutch {bead} {site}\n");
            if movable {
                bonds += &format!("tether {site} {pin}\n");
            }
            if k > 0 {
                bonds += &format!("segment {} {bead}\n", bead - 3);
            }
        }
        // A clutch that breaks only beyond 1000 % strain (it settles at 280 %): deterministic at T = 0.
        let site = if movable { "particle site drag 1" } else { "particle site fixed" };
        let ff = format!(
            "particle actin drag 1\n{site}\nparticle pin fixed\nbond segment harmonic k 50 r0 0.5\nbond tether harmonic k 20 r0 0.05\n\
             bond clutch harmonic k 5 r0 0.05 kinetics threshold strain 10\n"
        );
        let deck = format!(
            "units cell\ntopology t.top\nforcefield f.ff\nbox x -5 10 f y -5 5 f z -5 5 f\ngroup actin type actin\n\
             external pull actin constant_force fx {f}\ntimestep 1e-3\nthermo 30000 step tension/clutch nbound/clutch tension/tether\n\
             thermo_file t.csv\nrun 30000\n"
        );
        let c = Case::new(&[("t.top", &(top + &bonds)), ("f.ff", &ff), ("deck.in", &deck)]);
        c.run();
        let thermo = std::fs::read_to_string(c.path("t.csv")).unwrap();
        let last: Vec<f64> = thermo.lines().last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(last[2], n as f64, "every clutch still bound");
        let load = n as f64 * f;
        assert!((last[1] - load).abs() < 1e-9 * load, "movable {movable}: traction {} pN against a pull of {load} pN", last[1]);
        let tether = if movable { load } else { 0.0 };
        assert!((last[3] - tether).abs() < 1e-9 * load, "movable {movable}: tethers carry {} pN", last[3]);
    }
}

/// A step too coarse to resolve a bond's lifetime (k·dt > 0.1) is run with
/// the exact survival probability but warned about, once per bond type, naming
/// the type and its k·dt.
#[test]
fn coarse_steps_are_warned_about_once_per_bond_type() {
    let bond = "bond f0 harmonic k 10 r0 1 kinetics slip k0 50 x_beta 0.1";
    let c = case(&parallel_bonds(50, &[1.0]), bond, "temperature 1\ntimestep 0.01\nseed 2\nrun 5\n");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
        .arg("run")
        .arg(c.path("deck.in"))
        .arg("-o")
        .arg(c.output_dir())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("bond type `f0` has k_off·dt = 0.500"), "{}", warnings[0]);
}

/// (step, time) of every row of a thermo CSV whose first two columns are
/// `step` and `time`.
fn thermo_times(case: &Case, file: &str) -> std::collections::HashMap<u64, f64> {
    let text = std::fs::read_to_string(case.path(file)).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().unwrap(), f[1].parse().unwrap())
        })
        .collect()
}

/// Event times come from the run's clock, not from step × dt: after a deck
/// changes `timestep` between runs, each event's time is the thermo time of
/// its step (before the fix, the second run's events were stamped up to
/// 0.1 s late).
#[test]
fn event_times_equal_thermo_times_when_the_timestep_changes() {
    let c = case(
        &fixed_pairs(400, &[1.0]),
        "bond b harmonic k 10 r0 1 kinetics slip k0 5 x_beta 0.5",
        "temperature 1\nseed 5\nevents events.csv\nthermo 1 step time\nthermo_file thermo.csv\n\
         timestep 5e-4\nrun 200\ntimestep 1e-3\nrun 200\n",
    );
    c.run();
    let thermo = thermo_times(&c, "thermo.csv");
    let log = std::fs::read_to_string(c.path("events.csv")).unwrap();
    let (mut first, mut second) = (0, 0);
    for row in log.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        let (step, time): (u64, f64) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        if step < 200 {
            first += 1;
        } else {
            second += 1;
        }
        assert_eq!(time, thermo[&step], "event at step {step}: time {time}, thermo time {}", thermo[&step]);
    }
    assert!(first > 20 && second > 20, "too few events to test: {first} in the first run, {second} in the second");
}
