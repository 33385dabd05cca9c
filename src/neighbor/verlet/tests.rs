use super::*;

/// splitmix64: a tiny deterministic generator for test configurations.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
}

fn brute_force(x: &[DVec3], b: &SimBox, range: f64, ex: &Exclusions) -> Vec<Vec<u32>> {
    (0..x.len())
        .map(|i| {
            (0..x.len())
                .filter(|&j| j != i && !ex.is_excluded(i as u32, j as u32) && b.minimum_image(x[j] - x[i]).length_squared() < range * range)
                .map(|j| j as u32)
                .collect()
        })
        .collect()
}

fn assert_matches_brute_force(x: &[DVec3], b: &SimBox, cutoff: f64, skin: f64, ex: &Exclusions) -> NeighborList {
    let mut list = NeighborList::new(cutoff, skin);
    list.build(x, b, ex).unwrap();
    let expected = brute_force(x, b, cutoff + skin, ex);
    assert_eq!(list.len(), x.len());
    for (i, want) in expected.iter().enumerate() {
        assert_eq!(list.neighbors(i), &want[..], "particle {i} at {} (grid {:?})", x[i], list.grid());
    }
    let total: usize = expected.iter().map(Vec::len).sum();
    assert_eq!(list.num_pairs() * 2, total);
    for (i, want) in expected.iter().enumerate().step_by(7) {
        assert_eq!(list.partners(i), *want);
    }
    // The half list is the upper triangle of the same pair set.
    let mut half = NeighborList::half(cutoff, skin);
    half.build(x, b, ex).unwrap();
    assert!(half.is_half() && !list.is_half());
    for (i, want) in expected.iter().enumerate() {
        let upper: Vec<u32> = want.iter().copied().filter(|&j| j as usize > i).collect();
        assert_eq!(half.neighbors(i), &upper[..], "half list, particle {i}");
    }
    assert_eq!(half.num_pairs(), list.num_pairs());
    for (i, want) in expected.iter().enumerate().step_by(7) {
        assert_eq!(half.partners(i), *want, "all partners from the half list");
    }
    list
}

fn random_positions(rng: &mut Rng, n: usize, lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    (0..n).map(|_| DVec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z))).collect()
}

const PERIODICITIES: [[bool; 3]; 4] = [[true, true, true], [false, false, false], [true, true, false], [false, true, false]];

#[test]
fn matches_brute_force_dense_and_sparse() {
    let mut rng = Rng(1);
    let b_lo = DVec3::new(-3.0, 1.0, 0.5);
    let b_hi = DVec3::new(7.0, 9.0, 12.5);
    for periodic in PERIODICITIES {
        let b = SimBox::new(b_lo, b_hi, periodic);
        for &(n, cutoff, skin) in &[(600, 1.0, 0.3), (60, 1.2, 0.4), (300, 0.35, 0.05), (400, 2.0, 0.0)] {
            let x = random_positions(&mut rng, n, b_lo, b_hi);
            let list = assert_matches_brute_force(&x, &b, cutoff, skin, &Exclusions::none());
            assert!(list.grid().iter().product::<usize>() > 1);
        }
    }
}

#[test]
fn matches_brute_force_with_exclusions() {
    let mut rng = Rng(2);
    let b = SimBox::new(DVec3::ZERO, DVec3::new(6.0, 6.0, 6.0), [true, false, true]);
    let x = random_positions(&mut rng, 400, b.lo, b.hi);
    let mut pairs: Vec<(u32, u32)> = (0..399).map(|i| (i, i + 1)).collect();
    for _ in 0..500 {
        pairs.push((rng.below(400) as u32, rng.below(400) as u32));
    }
    let ex = Exclusions::from_pairs(400, &pairs);
    let list = assert_matches_brute_force(&x, &b, 1.0, 0.25, &ex);
    for &(i, j) in &pairs {
        assert!(!list.neighbors(i as usize).contains(&j));
    }
}

/// Three types of which only (0, 1) and (2, 2) interact, with pair
/// exclusions too: the list is the brute-force one with both left out.
#[test]
fn matches_brute_force_with_excluded_type_pairs() {
    let mut rng = Rng(5);
    let b = SimBox::new(DVec3::ZERO, DVec3::new(6.0, 6.0, 6.0), [true, true, false]);
    let x = random_positions(&mut rng, 400, b.lo, b.hi);
    let types: Vec<u32> = (0..400).map(|_| rng.below(3) as u32).collect();
    let pairs: Vec<(u32, u32)> = (0..399).map(|i| (i, i + 1)).collect();
    let ex = Exclusions::from_pairs(400, &pairs).with_type_pairs(&types, 3, |a, b| !matches!((a, b), (0, 1) | (2, 2)));
    let list = assert_matches_brute_force(&x, &b, 1.0, 0.25, &ex);
    let unfiltered = assert_matches_brute_force(&x, &b, 1.0, 0.25, &Exclusions::from_pairs(400, &pairs));
    assert!(list.num_pairs() > 100 && 2 * list.num_pairs() < unfiltered.num_pairs(), "{} of {}", list.num_pairs(), unfiltered.num_pairs());
    for i in 0..400 {
        for &j in list.neighbors(i) {
            let t = [types[i], types[j as usize]];
            assert!(matches!(t, [0, 1] | [1, 0] | [2, 2]), "pair {i}-{j} of types {t:?}");
        }
    }
}

#[test]
fn particles_on_and_outside_boundaries() {
    let mut rng = Rng(3);
    let lo = DVec3::new(0.0, -2.0, 1.0);
    let hi = DVec3::new(5.0, 3.0, 6.0);
    let (cutoff, skin) = (0.8, 0.2);
    for periodic in PERIODICITIES {
        let b = SimBox::new(lo, hi, periodic);
        let mut x = random_positions(&mut rng, 150, lo, hi);
        // Exactly on faces, one ulp inside the upper face, on cell edges.
        let below = |v: f64| f64::from_bits(v.to_bits() - 1);
        for &(fx, fy, fz) in &[(0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (0.5, 1.0, 0.0), (1.0, 0.5, 0.2)] {
            let p = lo + DVec3::new(fx, fy, fz) * (hi - lo);
            x.push(p);
            x.push(DVec3::new(below(p.x.max(lo.x + 1e-300)), p.y, p.z));
        }
        x.push(DVec3::new(below(hi.x), below(hi.y), below(hi.z)));
        x.push(DVec3::new(lo.x + 1.0, lo.y + 2.0, lo.z + 3.0)); // cell edges (w = 1)
        x.push(DVec3::new(lo.x + 2.0, lo.y + 2.0, lo.z + 3.0));
        // Outside the box on non-periodic axes (wrapped on periodic ones by
        // the integrator, but the list must cope with unwrapped input too).
        for _ in 0..40 {
            let mut p = DVec3::new(rng.range(-2.0, 7.0), rng.range(-4.0, 5.0), rng.range(-1.0, 8.0));
            for a in 0..3 {
                if periodic[a] {
                    p[a] = rng.range(lo[a], hi[a]);
                }
            }
            x.push(p);
        }
        x.push(DVec3::new(-1e6, -1e6, 1e6));
        assert_matches_brute_force(&x, &b, cutoff, skin, &Exclusions::none());
    }
}

#[test]
fn unwrapped_periodic_positions_are_still_found() {
    let mut rng = Rng(9);
    let b = SimBox::new(DVec3::ZERO, DVec3::splat(5.0), [true; 3]);
    let x: Vec<DVec3> = random_positions(&mut rng, 200, DVec3::splat(-10.0), DVec3::splat(15.0));
    assert_matches_brute_force(&x, &b, 1.0, 0.2, &Exclusions::none());
}

#[test]
fn one_and_two_cells_per_axis() {
    let mut rng = Rng(4);
    let (cutoff, skin) = (1.0, 0.25);
    let r = cutoff + skin;
    // Edges of exactly 2r (one cell), 2.5r (two cells) and 3.5r (three).
    for lengths in [DVec3::splat(2.0 * r), DVec3::splat(2.5 * r), DVec3::new(2.0 * r, 2.5 * r, 3.5 * r)] {
        for periodic in PERIODICITIES {
            let b = SimBox::new(DVec3::splat(-1.0), DVec3::splat(-1.0) + lengths, periodic);
            for n in [2, 30, 120] {
                let x = random_positions(&mut rng, n, b.lo, b.hi);
                let list = assert_matches_brute_force(&x, &b, cutoff, skin, &Exclusions::none());
                for a in 0..3 {
                    assert!(list.grid()[a] <= 3, "grid {:?}", list.grid());
                }
            }
        }
    }
    let b = SimBox::new(DVec3::ZERO, DVec3::splat(2.5 * r), [true; 3]);
    let x = random_positions(&mut rng, 10, b.lo, b.hi);
    let mut list = NeighborList::new(cutoff, skin);
    list.build(&x, &b, &Exclusions::none()).unwrap();
    assert_eq!(list.grid(), [2, 2, 2]);
}

#[test]
fn too_small_periodic_box_is_an_error() {
    let b = SimBox::new(DVec3::ZERO, DVec3::new(10.0, 2.3, 10.0), [true, true, false]);
    let mut list = NeighborList::new(1.0, 0.2);
    let err = list.build(&[DVec3::ONE], &b, &Exclusions::none()).unwrap_err();
    assert!(err.contains("along y") && err.contains("2.4"), "{err}");
    assert_eq!(list.builds(), 0);
    // The same edge on a non-periodic axis is fine.
    let b = SimBox::new(DVec3::ZERO, DVec3::new(10.0, 10.0, 2.3), [true, true, false]);
    list.build(&[DVec3::ONE], &b, &Exclusions::none()).unwrap();
    assert_eq!(list.builds(), 1);
}

#[test]
fn invalid_inputs_are_errors() {
    let b = SimBox::new(DVec3::ZERO, DVec3::splat(10.0), [true; 3]);
    let x = [DVec3::ONE, DVec3::new(f64::NAN, 0.0, 0.0)];
    let err = NeighborList::new(1.0, 0.1).build(&x, &b, &Exclusions::none()).unwrap_err();
    assert!(err.contains("particle 1") && err.contains("non-finite"), "{err}");
    let err = NeighborList::new(-1.0, 0.1).build(&x[..1], &b, &Exclusions::none()).unwrap_err();
    assert!(err.contains("cutoff"), "{err}");
    let err = NeighborList::new(1.0, f64::NAN).build(&x[..1], &b, &Exclusions::none()).unwrap_err();
    assert!(err.contains("skin"), "{err}");
    let inverted = SimBox::new(DVec3::ZERO, DVec3::new(10.0, -1.0, 10.0), [false; 3]);
    let err = NeighborList::new(1.0, 0.1).build(&x[..1], &inverted, &Exclusions::none()).unwrap_err();
    assert!(err.contains("along y"), "{err}");
}

#[test]
fn zero_cutoff_and_no_particles() {
    let b = SimBox::new(DVec3::ZERO, DVec3::splat(1e9), [true; 3]);
    let x = vec![DVec3::ONE; 5];
    let mut list = NeighborList::new(0.0, 0.0);
    list.build(&x, &b, &Exclusions::none()).unwrap();
    assert_eq!(list.len(), 5);
    assert_eq!(list.num_pairs(), 0);
    assert!((0..5).all(|i| list.neighbors(i).is_empty()));
    assert_eq!(list.grid(), [0; 3]);
    assert!(!list.needs_rebuild(&[DVec3::splat(3.0); 5], &b));
    assert!(list.needs_rebuild(&[DVec3::ONE; 4], &b));

    let mut list = NeighborList::new(1.0, 0.3);
    list.build(&[], &b, &Exclusions::none()).unwrap();
    assert!(list.is_empty());
    assert_eq!(list.offsets(), &[0]);
    assert!(!list.needs_rebuild(&[], &b));
}

#[test]
fn huge_box_tiny_cutoff_caps_the_grid() {
    let mut rng = Rng(5);
    let b = SimBox::new(DVec3::ZERO, DVec3::splat(1e6), [true, true, false]);
    let mut x = random_positions(&mut rng, 100, b.lo, b.hi);
    // A tight cluster so that some pairs exist.
    for k in 0..50 {
        let jitter = DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 6e-4;
        x.push(DVec3::new(5.0, 5.0, 5.0 + k as f64 * 2e-4) + jitter);
    }
    let list = assert_matches_brute_force(&x, &b, 1e-3, 1e-4, &Exclusions::none());
    let cells: usize = list.grid().iter().product();
    assert!(cells <= 8 * x.len(), "grid {:?}", list.grid());
    assert!(list.num_pairs() > 0);
}

#[test]
fn identical_for_any_thread_count_and_rebuild_time() {
    let mut rng = Rng(6);
    let b = SimBox::new(DVec3::ZERO, DVec3::splat(8.0), [true, true, false]);
    let x = random_positions(&mut rng, 1500, b.lo, b.hi);
    let build_with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut list = NeighborList::new(1.0, 0.3);
            list.build(&x, &b, &Exclusions::none()).unwrap();
            (list.offsets().to_vec(), list.flat().to_vec())
        })
    };
    assert_eq!(build_with(1), build_with(3));

    // A list built from slightly earlier positions, filtered to the cutoff,
    // gives the same ordered pairs as a fresh one.
    let mut early = NeighborList::new(1.0, 0.4);
    let x0: Vec<DVec3> = x.iter().map(|p| *p + DVec3::new(0.05, -0.05, 0.0)).collect();
    early.build(&x0, &b, &Exclusions::none()).unwrap();
    assert!(!early.needs_rebuild(&x, &b));
    let mut fresh = NeighborList::new(1.0, 0.4);
    fresh.build(&x, &b, &Exclusions::none()).unwrap();
    for i in 0..x.len() {
        let within = |l: &NeighborList| -> Vec<u32> {
            l.neighbors(i).iter().copied().filter(|&j| b.minimum_image(x[j as usize] - x[i]).length() < 1.0).collect()
        };
        assert_eq!(within(&early), within(&fresh));
    }
}

#[test]
fn rebuild_criterion_is_half_the_skin() {
    let b = SimBox::new(DVec3::ZERO, DVec3::splat(10.0), [true, true, false]);
    let x = vec![DVec3::new(9.95, 5.0, 5.0), DVec3::new(2.0, 2.0, 2.0)];
    let mut list = NeighborList::new(1.0, 0.4);
    assert!(list.needs_rebuild(&x, &b), "never built");
    list.build(&x, &b, &Exclusions::none()).unwrap();
    assert_eq!(list.builds(), 1);
    assert!(!list.needs_rebuild(&x, &b));

    let moved = |d: DVec3| vec![x[0], x[1] + d];
    assert!(!list.needs_rebuild(&moved(DVec3::new(0.0, 0.19, 0.0)), &b));
    assert!(list.needs_rebuild(&moved(DVec3::new(0.0, 0.21, 0.0)), &b));
    assert!(!list.needs_rebuild(&moved(DVec3::new(0.1, 0.1, 0.1)), &b)); // |d| ≈ 0.173
    assert!(list.needs_rebuild(&moved(DVec3::new(0.0, 0.0, -0.25)), &b));

    // Across the periodic x face: 9.95 → 0.05 (wrapped) is a move of 0.1.
    let wrapped = vec![DVec3::new(0.05, 5.0, 5.0), x[1]];
    assert!(!list.needs_rebuild(&wrapped, &b));
    let wrapped = vec![DVec3::new(0.2, 5.0, 5.0), x[1]];
    assert!(list.needs_rebuild(&wrapped, &b));

    // Box or particle-count changes.
    let other = SimBox::new(DVec3::ZERO, DVec3::splat(11.0), [true, true, false]);
    assert!(list.needs_rebuild(&x, &other));
    assert!(list.needs_rebuild(&x[..1], &b));

    list.build(&wrapped, &b, &Exclusions::none()).unwrap();
    assert_eq!(list.builds(), 2);
    assert!(!list.needs_rebuild(&wrapped, &b));
}
