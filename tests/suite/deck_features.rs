//! Deck features end to end: variables, continuation lines, repeated commands,
//! parameter changes between runs, groups, externals and dumps.

use crate::common::Case;
use cellmd::deck::{validate_file, Action};
use cellmd::run::{RunOptions, Simulation};

const TOP: &str = "[ particles ]\n1 p 0 0 0\n2 p 1.5 0 0\n3 q 5 5 5\n4 q 6 5 5\n[ bonds ]\ns 1 2\n";
const FF: &str = "particle p drag 2\nparticle q radius 0.5 viscosity 0.1\nbond s harmonic k 3 r0 1\n";

fn deck(body: &str) -> Case {
    let header = "units lj\ntopology t.top\nforcefield f.ff\nbox x -20 20 f y -20 20 f z -20 20 f\ntimestep 0.001\n";
    Case::new(&[("t.top", TOP), ("f.ff", FF), ("deck.in", &format!("{header}{body}"))])
}

#[test]
fn variables_expressions_continuations_and_overrides() {
    let case = deck("variable n equal 2*(3+2)\nvariable dt equal 1/1000\ntimestep ${dt}\nrun &\n   ${n}\n");
    let plan = case.plan();
    let runs: Vec<u64> = plan.actions.iter().filter_map(|a| if let Action::Run(n) = a { Some(*n) } else { None }).collect();
    assert_eq!(runs, vec![10]);
    let overridden = validate_file(&case.path("deck.in"), &[("n".into(), "7".into())]).unwrap();
    assert!(overridden.actions.iter().any(|a| matches!(a, Action::Run(7))));
}

#[test]
fn stokes_drag_and_types_resolve() {
    let plan = deck("run 0\n").plan();
    assert_eq!(plan.model.type_drag[0], 2.0);
    assert!((plan.model.type_drag[1] - 6.0 * std::f64::consts::PI * 0.1 * 0.5).abs() < 1e-15);
}

#[test]
fn coeff_changes_the_rest_length_between_runs() {
    // kT = 0: the dimer relaxes to r0 = 1, then to the new r0 = 2.
    let case = deck("run 20000\nwrite_state a.state\ncoeff bond s r0 2\nrun 20000\n");
    let sim = case.run();
    let first = cellmd::output::restart::read_state(&case.path("a.state")).unwrap().to_state();
    let r1 = (first.positions[1] - first.positions[0]).length();
    let r2 = (sim.state.positions[1] - sim.state.positions[0]).length();
    // Relaxation rate 2k/γ = 3 per unit time, 20 time units: fully relaxed.
    assert!((r1 - 1.0).abs() < 1e-12, "r after first run {r1}");
    assert!((r2 - 2.0).abs() < 1e-12, "r after coeff {r2}");
    // The plan's model keeps the original value; the change is an action.
    assert_eq!(case.plan().model.bond_types[0].params, vec![3.0, 1.0]);
}

#[test]
fn groups_select_by_type_and_id_and_externals_come_and_go() {
    let case = deck(
        "group movers type q\ngroup first id 1:1\nexternal push movers constant_force fx 1\nrun 1000\nwrite_state a.state\n\
         unexternal push\nexternal push first constant_force fy 2\nrun 1000\n",
    );
    let sim = case.run();
    let mid = cellmd::output::restart::read_state(&case.path("a.state")).unwrap().to_state();
    let gamma_q = 6.0 * std::f64::consts::PI * 0.1 * 0.5;
    // Type q moved in x at F/γ for 1 time unit; nothing else felt the push.
    assert!((mid.positions[2].x - (5.0 + 1.0 / gamma_q)).abs() < 1e-12);
    assert_eq!(mid.positions[2].y, 5.0);
    // After the swap, q stops and particle 1 is pushed in y.
    assert_eq!(sim.state.positions[2], mid.positions[2]);
    assert!(sim.state.positions[0].y > 0.1);
}

#[test]
fn lammps_and_xyz_dumps_through_the_deck() {
    let case = deck("dump a every 10 lammps a.dump\ndump b every 5 xyz b.xyz\nrun 20\nundump a\nrun 10\n");
    case.run();
    let lammps = std::fs::read_to_string(case.path("a.dump")).unwrap();
    // Frames at 0, 10, 20 (closed before the second run).
    assert_eq!(lammps.matches("ITEM: TIMESTEP").count(), 3);
    assert!(lammps.contains("ITEM: ATOMS id type element x y z ix iy iz"));
    let xyz = std::fs::read_to_string(case.path("b.xyz")).unwrap();
    // Frames at 0, 5, 10, 15, 20, 25, 30: 7 frames of 4 + 2 lines.
    assert_eq!(xyz.lines().count(), 7 * 6);
}

#[test]
fn thermo_prints_requested_columns_to_csv() {
    let case = deck("thermo 5 step pe pe/harmonic fnorm pxx nbuild\nthermo_file t.csv\nrun 10\n");
    case.run();
    let csv = std::fs::read_to_string(case.path("t.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "step[-],pe[ε],pe/harmonic[ε],fnorm[ε/σ],pxx[ε/σ³],nbuild[-]");
    assert_eq!(lines.len(), 4);
    // At step 0 the bond is stretched by 0.5: E = ½·3·0.25 and |F| = 1.5 on each end.
    let row: Vec<f64> = lines[1].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(row[1], 0.375);
    assert_eq!(row[2], 0.375);
    assert!((row[3] - 1.5 * 2f64.sqrt()).abs() < 1e-12);
    // Virial W_xx = r_ij·f_ij with r_ij = r_1 − r_2 = −1.5 and the tension
    // pulling 1 towards 2, f_ij = +1.5: a stretched bond gives P_xx = −2.25/V (kT = 0).
    assert!((row[4] + 2.25 / 40f64.powi(3)).abs() < 1e-15, "pxx = {}", row[4]);
}

/// `displace_atoms` moves a fixed anchor across the periodic boundary at
/// x = 5; `xu/GROUP` follows it unwrapped, `fx/GROUP` reads the spring's
/// pull on it (k = 3, r0 = 1, bead at x = 1), `fx/all` sums to zero, and
/// `minimize` relaxes the bead without moving the loaded anchor.
#[test]
fn displace_atoms_moves_a_group_and_group_columns_read_its_position_and_load() {
    let top = "[ particles ]\n1 a 0 0 0\n2 p 1 0 0\n[ bonds ]\ns 1 2\n";
    let ff = "particle a fixed\nparticle p drag 1\nbond s harmonic k 3 r0 1\n";
    let body = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 5 p y -5 5 f z -5 5 f\ntimestep 0.01\n\
                group anchor type a\nthermo 0 xu/anchor fx/anchor fx/all\nthermo_file t.csv\n\
                displace_atoms anchor move 4.5 0 0\nrun 0\ndisplace_atoms anchor move 1 0 0\nrun 0\nminimize ftol 1e-10\nrun 0\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", body)]);
    let sim = case.run();
    let csv = std::fs::read_to_string(case.path("t.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(csv.lines().next().unwrap(), "xu/anchor[σ],fx/anchor[ε/σ],fx/all[ε/σ]");
    // Anchor at 4.5: the bead 3.5 away, stretched by 2.5, pulls it by 3·2.5 towards −x.
    assert_eq!(rows[0][0], 4.5);
    assert!((rows[0][1] + 7.5).abs() < 1e-12 && rows[0][2].abs() < 1e-12, "{:?}", rows[0]);
    // Anchor at 5.5 (wrapped to −4.5): the bead 4.5 away through the boundary.
    assert!((rows[1][0] - 5.5).abs() < 1e-12 && (rows[1][1] + 10.5).abs() < 1e-12, "{:?}", rows[1]);
    assert_eq!((sim.state.positions[0].x, sim.state.images[0][0]), (-4.5, 1));
    // Relaxed: the bead sits r0 from the anchor, which has not moved.
    assert!((rows[2][0] - 5.5).abs() < 1e-12 && rows[2][1].abs() < 1e-9, "{:?}", rows[2]);
}

#[test]
fn the_same_deck_twice_writes_identical_files() {
    let body = "temperature 1\nseed 4\ndump a every 10 mcap a.mcap\nthermo 10\nthermo_file t.csv\nrun 50\n";
    let (one, two) = (deck(body), deck(body));
    for case in [&one, &two] {
        let plan = case.plan();
        Simulation::execute(plan, RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }).unwrap();
    }
    for file in ["a.mcap", "t.csv"] {
        assert_eq!(std::fs::read(one.path(file)).unwrap(), std::fs::read(two.path(file)).unwrap(), "{file} differs");
    }
}
