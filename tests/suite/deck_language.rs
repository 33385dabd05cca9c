//! The deck language of issue 18 (part A): loops and `if`s (decided when the
//! deck is read, or during the run from thermo values), thermo per external
//! and the work of constant forces, externals whose parameters are
//! expressions of x, y, z and t (`field`, a moving wall), the temperature
//! guard. The bad forms are in tests/decks/bad/ (tests/suite/bad_decks.rs).

use crate::common::Case;
use cellmd::deck::{Action, Plan, ThermoColumn};
use cellmd::export::{export, ExportOptions};
use cellmd::run::Simulation;

/// One bead of drag 1 at the origin, LJ units, dt = 0.01, then `body`.
fn bead(body: &str) -> Case {
    let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -50 50 f y -5 5 f z -5 5 f\ntimestep 0.01\n{body}");
    Case::new(&[("t.top", "[ particles ]\n1 p 0 0 0\n"), ("f.ff", "particle p drag 1\n"), ("deck.in", &deck)])
}

fn runs(plan: &Plan) -> Vec<u64> {
    plan.actions.iter().filter_map(|a| if let Action::Run(n) = a { Some(*n) } else { None }).collect()
}

/// The value of the plan's last thermo column named `label` at the end of the run.
fn column(sim: &mut Simulation, plan: &Plan, label: &str) -> f64 {
    let columns = plan.actions.iter().rev().find_map(|a| if let Action::Thermo { columns, .. } = a { Some(columns.clone()) } else { None });
    let c: ThermoColumn = columns
        .unwrap()
        .into_iter()
        .find(|c| cellmd::run::thermo::column_label(c, &plan.model) == label)
        .unwrap_or_else(|| panic!("no column {label}"));
    sim.thermo_value(&c).unwrap()
}

#[test]
fn loops_unroll_with_their_variable_and_a_decided_break_ends_them() {
    let case = bead("loop i 1 3\n  run ${i}\n  loop j 1 2\n    run 1\n  endloop\nendloop\nrun 7\n");
    assert_eq!(runs(&case.plan()), vec![1, 1, 1, 2, 1, 1, 3, 1, 1, 7]);
    // The loop variable is an expression name too, and is gone after the loop.
    let case = bead("variable i string before\nloop i 2 5\n  if i > 3 then\n    break\n  endif\n  run 2*i\nendloop\nprint ${i}\n");
    let err = cellmd::deck::validate_file(&case.path("deck.in"), &[]).unwrap_err().to_string();
    assert!(err.contains("found `2*i`, expected a number of steps"), "{err}");
    let case = bead("variable i string before\nloop i 2 5\n  if i > 3 then\n    break\n  endif\n  variable n equal 2*i\n  run ${n}\nendloop\nprint ${i}\n");
    let plan = case.plan();
    assert_eq!(runs(&plan), vec![4, 6]);
    assert!(matches!(plan.actions.last(), Some(Action::Print(text)) if text == "before"), "{:?}", plan.actions.last());
}

#[test]
fn a_run_time_if_breaks_a_loop_when_a_thermo_value_crosses() {
    // Pulled at unit force and unit drag the bead moves 0.1 per run of 10
    // steps: x = 0.5 after five runs, 0.6 after six, when the loop stops.
    let case = bead(
        "external pull all constant_force fx 1\nloop k 1 100\n  run 10\n  if thermo(xu/all) > 0.55 then\n    print stop\n    break\n  endif\nendloop\nrun 5\n",
    );
    let sim = case.run();
    assert_eq!(sim.state.step, 65);
    assert!((sim.state.positions[0].x - 0.65).abs() < 1e-12, "{}", sim.state.positions[0].x);
    // Outside a loop, the else branch runs when the condition fails; names are read where the `if` stands.
    let case = bead(
        "variable limit equal 1\nrun 10\nif thermo(xu/all) > limit || thermo(step) != 10 then\n  run 100\nelse\n  run 20\nendif\nrun 1\n",
    );
    assert_eq!(case.run().state.step, 31);
}

#[test]
fn previous_reads_a_column_at_the_ifs_last_decision_so_a_loop_stops_at_rest() {
    // In the trap F = −2(x − 1) from x = 0 the bead moves 0.98^{50(k−1)}·(1 − 0.98^50)
    // in the k-th run of 50 steps: 0.231, 0.084, 0.031, 0.011, then 0.0041 < 0.01 at k = 6.
    let case = bead(
        "external trap all field fx \"-2*(x - 1)\"\nloop k 1 100\n  run 50\n  \
         if abs(thermo(xu/all) - previous(xu/all)) < 0.01 then\n    break\n  endif\nendloop\n",
    );
    assert_eq!(case.run().state.step, 300);
    // At its first decision the condition has no earlier value and does not hold, whatever it says.
    let case = bead("loop k 1 5\n  run 10\n  if !(previous(step) < 0) then\n    break\n  endif\nendloop\n");
    assert_eq!(case.run().state.step, 20);
    // An `if` is one place in the deck: in a nested loop its earlier decision may be from the outer loop's
    // previous iteration (steps 10, 20: break; then 30, where step 20 is previous: break).
    let case = bead("loop i 1 2\n  loop k 1 5\n    run 10\n    if previous(step) > 0 then\n      break\n    endif\n  endloop\nendloop\n");
    assert_eq!(case.run().state.step, 30);
}

#[test]
fn pe_leaves_out_the_work_of_constant_forces_and_externals_have_their_own_columns() {
    let case = bead(
        "external pull all constant_force fx 2 fy -1\nexternal floor all wall nx 1 d 0.5 k 4\nthermo 0 pe work pe/pull fx/pull fy/pull \
         pe/floor fx/floor pe/constant_force\nrun 0\n",
    );
    let plan = case.plan();
    let mut sim = Simulation::execute(plan.clone(), Default::default()).unwrap();
    // At x = 0: the wall holds the bead 0.5 inside, E = ½·4·0.5² = 0.5, F = 2 along x.
    let values: Vec<f64> = ["pe", "work", "pe/pull", "fx/pull", "fy/pull", "pe/floor", "fx/floor", "pe/constant_force"]
        .map(|l| column(&mut sim, &plan, l))
        .into();
    assert_eq!(values, vec![0.5, 0.0, -0.0, 2.0, -1.0, 0.5, 2.0, -0.0]);
    // Moved to x = 3, y = 1: the pull's potential −F·x = −5 is its work 5, not part of `pe`.
    let case = bead(
        "external pull all constant_force fx 2 fy -1\nexternal floor all wall nx 1 d 0.5 k 4\nthermo 0 pe work pe/pull fx/floor\n\
         displace_atoms all move 3 1 0\nrun 0\n",
    );
    let plan = case.plan();
    let mut sim = Simulation::execute(plan.clone(), Default::default()).unwrap();
    let values: Vec<f64> = ["pe", "work", "pe/pull", "fx/floor"].map(|l| column(&mut sim, &plan, l)).into();
    assert_eq!(values, vec![0.0, 5.0, -5.0, 0.0]);
}

#[test]
fn a_field_given_by_expressions_pulls_the_bead_into_its_trap() {
    // F = −2(x − x0) with x0 = 1 (a deck variable), energy (x − x0)²: the
    // bead relaxes by the factor (1 − 2·dt) per step.
    let case =
        bead("variable x0 equal 1\nexternal trap all field fx \"-2*(x - x0)\" e \"(x - x0)^2\"\nthermo 0 pe pe/trap fx/trap\nrun 1000\n");
    let plan = case.plan();
    let mut sim = Simulation::execute(plan.clone(), Default::default()).unwrap();
    let expected = 1.0 - 0.98f64.powi(1000);
    assert!((sim.state.positions[0].x - expected).abs() < 1e-12, "{} vs {expected}", sim.state.positions[0].x);
    let gap = 1.0 - sim.state.positions[0].x;
    assert!((column(&mut sim, &plan, "pe/trap") - gap * gap).abs() < 1e-20);
    assert!((column(&mut sim, &plan, "fx/trap") - 2.0 * gap).abs() < 1e-15);
    // Exported as fix addforce with atom-style variables.
    let input = export(&plan, ExportOptions::default()).unwrap().input;
    for line in [
        "variable x_trap_fx atom \"((-2.0)*(x-1.0))\"",
        "variable x_trap_e atom \"((x-1.0)^2.0)\"",
        "fix x_trap g_trap addforce v_x_trap_fx v_x_trap_fy v_x_trap_fz energy v_x_trap_e",
    ] {
        assert!(input.lines().any(|l| l == line), "in.lammps lacks `{line}`:\n{input}");
    }
}

#[test]
fn a_wall_whose_position_is_an_expression_of_time_drives_the_bead() {
    // d = 0.5·t with k·dt/drag = 1: each step puts the bead where the wall
    // was at the step's start, x_N = d(t_{N−1}) = 0.5·(N − 1)·dt, and the
    // wall's force is the drag of a bead at the wall's speed.
    let case = bead("external plate all wall nx 1 d \"0.5*t\" k 100\nthermo 0 fx/plate\nrun 1000\n");
    let plan = case.plan();
    let mut sim = Simulation::execute(plan.clone(), Default::default()).unwrap();
    assert!((sim.state.positions[0].x - 0.5 * 999.0 * 0.01).abs() < 1e-9, "{}", sim.state.positions[0].x);
    assert!((column(&mut sim, &plan, "fx/plate") - 0.5).abs() < 1e-6);
    // LAMMPS re-evaluates a wall face given as an equal-style variable of time
    // (the face sits rc = 100 below d, as for a fixed wall).
    let input = export(&plan, ExportOptions::default()).unwrap().input;
    for line in [
        "variable x_plate_face equal \"(0.5*time)-100.0\"",
        "fix x_plate g_plate wall/harmonic xlo v_x_plate_face 50.0 1.0 100.0 units box",
    ] {
        assert!(input.lines().any(|l| l == line), "in.lammps lacks `{line}`:\n{input}");
    }
    // A wall that depends on the position, or another parameter as a formula, has no LAMMPS form: a clear refusal.
    for external in ["external plate all wall nx 1 d \"0.1*y\" k 100\n", "external plate all wall nx 1 k \"100 + t\"\n"] {
        let err = export(&bead(&format!("{external}run 1\n")).plan(), ExportOptions::default()).unwrap_err();
        assert!(err.contains("external `plate`: expression parameters of `wall` are not exported"), "{err}");
    }
}

#[test]
fn a_temperature_below_one_kelvin_warns_that_it_is_in_kelvin() {
    let deck = |t: &str| {
        let deck = format!("topology t.top\nforcefield f.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntemperature {t}\ntimestep 0.01\nrun 1\n");
        Case::new(&[("t.top", "[ particles ]\n1 p 0 0 0\n"), ("f.ff", "particle p drag 1\n"), ("deck.in", &deck)])
    };
    let warnings = deck("0.0041").plan().warnings;
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].ends_with(
            "deck.in:4:13: warning: temperature 0.0041 K; did you mean kT? temperature is in kelvin (kT = 4.142e-3 pN·µm at 300 K)"
        ),
        "{}",
        warnings[0]
    );
    assert!(deck("300").plan().warnings.is_empty());
    assert!(deck("0").plan().warnings.is_empty());
}

#[test]
fn fractional_special_bonds_weigh_the_pair_terms_of_bonded_neighbours() {
    // A straight chain 1-2-3-4 at rest (bonds exert nothing) with an LJ pair
    // rule reaching every pair: only 1-3, 2-4 (r = 2) and 1-4 (r = 3) count.
    let case = |weights: &str| {
        let deck = format!(
            "units lj\nspecial_bonds lj {weights}\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\n\
             group tail id 4\ntimestep 0.001\nthermo 0 pe/lj fx/tail\nrun 0\n"
        );
        let top = "[ particles ]\n1 p 0 0 0\n2 p 1 0 0\n3 p 2 0 0\n4 p 3 0 0\n[ bonds ]\nb 1 2\nb 2 3\nb 3 4\n";
        let ff = "particle p drag 1\nbond b harmonic k 10 r0 1\npair p p lj epsilon 1 sigma 1 rc 5\n";
        let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", &deck)]);
        let plan = case.plan();
        let mut sim = Simulation::execute(plan.clone(), Default::default()).unwrap();
        [column(&mut sim, &plan, "pe/lj"), column(&mut sim, &plan, "fx/tail")]
    };
    let lj = |r: f64| 4.0 * (r.powi(-12) - r.powi(-6));
    let dlj = |r: f64| 4.0 * (-12.0 * r.powi(-13) + 6.0 * r.powi(-7));
    let [e, f] = case("0 0 0.5");
    assert!((e - 0.5 * lj(3.0)).abs() < 1e-15, "{e}");
    // On bead 4 the 1-4 pair pulls towards bead 1: F = −w·E'(3) along +x.
    assert!((f + 0.5 * dlj(3.0)).abs() < 1e-15, "{f}");
    let [e, f] = case("0 0.25 0.5");
    assert!((e - (0.25 * 2.0 * lj(2.0) + 0.5 * lj(3.0))).abs() < 1e-15, "{e}");
    assert!((f + 0.25 * dlj(2.0) + 0.5 * dlj(3.0)).abs() < 1e-15, "{f}");
    // Weights 0 and 1 stay what they were: a weight-1 pair is an ordinary neighbour.
    let [e, _] = case("0 1 1");
    assert!((e - (2.0 * lj(2.0) + lj(3.0))).abs() < 1e-15, "{e}");
}

#[test]
fn fractional_special_bonds_export_unchanged_and_may_run_on_the_gpu() {
    let deck = "units lj\nspecial_bonds lj 0.0 0.0 0.5\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\n\
                timestep 0.001\nrun 1\n";
    let top = "[ particles ]\n1 p 0 0 0\n2 p 1 0 0\n3 p 2 0 0\n4 p 3 0 0\n[ bonds ]\nb 1 2\nb 2 3\nb 3 4\n";
    let ff = "particle p drag 1\nbond b harmonic k 10 r0 1\npair p p lj epsilon 1 sigma 1 rc 5\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    let input = export(&plan, ExportOptions::default()).unwrap().input;
    assert!(input.lines().any(|l| l == "special_bonds lj 0.0 0.0 0.5"), "{input}");
    let sim = Simulation::new(&plan, Default::default());
    assert_eq!(sim.cpu_only_feature(), None);
}
