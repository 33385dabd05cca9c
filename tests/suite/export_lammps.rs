//! `cellmd export-lammps`: the conversions of each interaction, and clear
//! errors for what LAMMPS cannot express. (Agreement with LAMMPS itself is
//! checked by tests/suite/golden.rs and `scripts/test-all`.)

use crate::common::Case;
use cellmd::export::{export, ExportOptions};

const TOP: &str = "[ particles ]\n1 a 0 0 0.5\n2 a 1.1 0 0.5\n3 a 1.5 0.9 0.5\n[ bonds ]\nh 1 2\nc 2 3\n[ angles ]\nw 1 2 3\n";
const FF: &str = "particle a drag 2\nbond h harmonic k 50 r0 1\nbond c cable k 40 r0 1 tau 0.1\nangle w wlc_bending kappa 0.5 l0 0.25\n\
                  pair a a wca epsilon 1 sigma 1\npair a a lj epsilon 0.5 sigma 1 rc 2.5\n";

fn deck(extra: &str) -> Case {
    let deck =
        format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -5 5 p y -5 5 p z 0 5 f\n{extra}temperature 0\ntimestep 0.001\nrun 10\n");
    Case::new(&[("t.top", TOP), ("f.ff", FF), ("deck.in", &deck)])
}

#[test]
fn interactions_map_to_their_exact_lammps_forms() {
    let out = export(&deck("external floor all wall nz 1 d 0 k 20\n").plan(), ExportOptions::default()).unwrap();
    let input = out.input;
    for line in [
        "bond_style hybrid harmonic lepton no_offset",
        "bond_coeff 1 harmonic 25.0 1.0",
        "bond_coeff 2 lepton 1.0 \"0.5*40.0*1.0*max(0,r/1.0+(0.1))^2\"",
        "angle_coeff 1 cosine 2.0",
        "pair_style hybrid/overlay lj/cut 2.5 lj/cut 2.5",
        "pair_modify pair lj/cut 1 shift yes",
        "special_bonds lj 0.0 1.0 1.0",
        "boundary p p m",
        "fix x_floor g_floor wall/harmonic zlo -5.0 10.0 1.0 5.0 units box",
        "fix cellmd_bd1 cellmd_t1 brownian 1.0 1 gamma_t 2.0 rng none",
        "run 10 post no",
    ] {
        assert!(input.lines().any(|l| l == line), "in.lammps lacks `{line}`:\n{input}");
    }
    assert!(out.data.contains("3 atoms\n2 bonds\n1 angles\n"), "{}", out.data);
    // Probes only on request.
    assert!(!input.contains("write_dump"));
}

/// `displace_atoms … move` is LAMMPS' own command (in box units).
#[test]
fn displace_atoms_exports_as_lammps_displace_atoms() {
    let out = export(&deck("group tip id 2:3\ndisplace_atoms tip move 0.5 0 -0.25\n").plan(), ExportOptions::default()).unwrap();
    let expected = "group m_tip id 2:3\ndisplace_atoms m_tip move 0.5 0.0 -0.25 units box\ngroup m_tip delete\n";
    assert!(out.input.contains(expected), "{}", out.input);
}

#[test]
fn what_lammps_cannot_express_is_refused_by_name() {
    let oblique = export(&deck("external slope all wall nx 1 nz 1 k 20\n").plan(), ExportOptions::default()).unwrap_err();
    assert!(oblique.contains("external `slope`") && oblique.contains("oblique normal (1, 0, 1)"), "{oblique}");
    let periodic = export(&deck("external side all wall nx 1 nz 0 k 20\n").plan(), ExportOptions::default()).unwrap_err();
    assert!(periodic.contains("periodic axis x"), "{periodic}");
    let minimize = export(&deck("timestep 0.001\nminimize\n").plan(), ExportOptions::default()).unwrap_err();
    assert!(minimize.contains("`minimize`"), "{minimize}");
}

#[test]
fn cli_exports_files_and_exits_2_on_an_unexportable_deck() {
    let case = deck("");
    let out = case.path("lmp");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
        .args(["export-lammps", case.path("deck.in").to_str().unwrap(), out.to_str().unwrap(), "--probes"])
        .status()
        .unwrap();
    assert!(status.success());
    let input = std::fs::read_to_string(out.join("in.lammps")).unwrap();
    assert!(input.contains("read_data data.lammps") && input.contains("write_dump all custom cellmd_probe_init.dump"));
    assert!(out.join("data.lammps").exists());
    let bad = deck("external slope all wall nx 1 nz 1 k 20\n");
    let result = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
        .args(["export-lammps", bad.path("deck.in").to_str().unwrap(), bad.path("lmp").to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(result.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&result.stderr).contains("oblique normal"));
}

/// A deck with bond kinetics on three fixed particles: `ff` is the force
/// field after the particle line, `extra` goes before the first run.
fn kinetic_deck(ff: &str, extra: &str) -> Case {
    let top = "[ particles ]\n1 a 0 0 0\n2 a 1.1 0 0\n3 a 1.1 0.5 0\n[ bonds ]\ns 1 2\n";
    let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntimestep 0.01\n{extra}run 5\n");
    Case::new(&[("t.top", top), ("f.ff", &format!("particle a fixed\n{ff}")), ("deck.in", &deck)])
}

/// A strain `threshold` alone is `fix bond/break` at r0·(1 + S); certain
/// mutual-nearest binding is `fix bond/create` (with a `zero` pair style
/// reaching the capture radius, and room for the new bonds); the probes list
/// the bonds.
#[test]
fn expressible_kinetics_map_to_bond_break_and_bond_create() {
    let ff = "bond s harmonic k 5 r0 1.0 kinetics threshold strain 0.25\nbond link harmonic k 1 r0 0.5\n\
              bind a a link k_on 1e9 capture 0.8 max_bonds 2 partner nearest\n";
    let out = export(&kinetic_deck(ff, "").plan(), ExportOptions { probes: true }).unwrap();
    let input = out.input;
    for line in [
        "read_data data.lammps extra/bond/per/atom 2 extra/special/per/atom 21",
        "pair_style zero 0.8",
        "pair_coeff * *",
        "fix cellmd_break1 all bond/break 1 1 1.25",
        "fix cellmd_bind1 all bond/create 1 1 1 0.8 2 iparam 2 1 jparam 2 1",
        "compute cellmd_bonds all property/local btype batom1 batom2",
        "write_dump all local cellmd_probe_final.bonds index c_cellmd_bonds[1] c_cellmd_bonds[2] c_cellmd_bonds[3]",
    ] {
        assert!(input.lines().any(|l| l == line), "in.lammps lacks `{line}`:\n{input}");
    }
    // With other pair styles, `zero` joins the overlay.
    let with_pairs =
        export(&kinetic_deck(&format!("{ff}pair a a wca epsilon 1 sigma 0.5\n"), "").plan(), ExportOptions::default()).unwrap();
    assert!(with_pairs
        .input
        .contains("pair_style hybrid/overlay lj/cut 0.5612310241546865 zero 0.8\npair_coeff * * none\npair_coeff * * zero\n"));
    // A new r0 moves the break length.
    let coeff = export(&kinetic_deck(ff, "run 1\ncoeff bond s r0 2\n").plan(), ExportOptions::default()).unwrap();
    assert!(coeff.input.contains("unfix cellmd_break1\nfix cellmd_break1 all bond/break 1 1 2.5\n"), "{}", coeff.input);
}

#[test]
fn kinetics_lammps_cannot_express_are_refused_with_the_reason() {
    let link = "bond link harmonic k 1 r0 0.5\n";
    for (ff, extra, expected) in [
        ("bond s harmonic k 5 r0 1 kinetics slip k0 1 x_beta 0.1\n", "temperature 1\n", "no force-dependent bond kinetics"),
        ("bond s harmonic k 5 r0 1 kinetics threshold force 3\n", "", "only a `threshold` with a `strain` alone"),
        ("bond s harmonic k 5 r0 1 kinetics threshold strain 0.2 rate 5\n", "", "only a `threshold` with a `strain` alone"),
        ("bond s fene K 30 R0 1.5 epsilon 1 sigma 1 kinetics threshold strain 0.2\n", "", "has no `r0`"),
        ("bond s harmonic k 5 r0 1\nbind a a link k_on 1e9 capture 0.8\n", "", "`partner random`"),
        ("bond s harmonic k 5 r0 1\nbind a a link k_on 10 capture 0.8 partner nearest\n", "", "not certain within a step"),
        (
            "bond s harmonic k 5 r0 1\nbind a a link k_on 1e9 capture 0.8 partner nearest\n",
            "special_bonds 0 0 1\n",
            "`special_bonds` excludes",
        ),
        ("bond s harmonic k 5 r0 1\nbind a a s k_on 1e9 capture 0.8 partner nearest\n", "", ""),
        (
            "bond s harmonic k 5 r0 1 kinetics threshold strain 0.2\nbind a a s k_on 1e9 capture 0.8 partner nearest\n",
            "",
            "also has kinetic rules",
        ),
    ] {
        let ff = if ff.contains("bind a a link") { format!("{ff}{link}") } else { ff.to_string() };
        let result = export(&kinetic_deck(&ff, extra).plan(), ExportOptions::default());
        match expected {
            "" => assert!(result.is_ok(), "{ff}: {result:?}"),
            _ => {
                let err = result.unwrap_err();
                assert!(err.contains(expected), "{ff}: expected `{expected}` in `{err}`");
            }
        }
    }
}

/// Bonds with their own r0: one LAMMPS bond type per distinct (type, r0)
/// after the cellmd types (a per-bond r0 equal to its type's stays on the
/// type's); `coeff` rewrites every LAMMPS type of its cellmd type, and a
/// strain threshold breaks each at its own r0·(1 + S).
#[test]
fn per_bond_rest_lengths_become_bond_types_of_their_own() {
    let top =
        "[ particles ]\n1 a 0 0 0\n2 a 1.1 0 0\n3 a 1.1 0.5 0\n4 a 2 0.5 0\n[ bonds ]\ns 1 2 1.2\nt 2 3\ns 3 4 1.0\ns 1 3 1.2\nt 1 4 0.7\n";
    let ff = "particle a fixed\nbond s harmonic k 5 r0 1.0 kinetics threshold strain 0.25\nbond t harmonic k 3 r0 0.5\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntimestep 0.01\nrun 1\ncoeff bond s k 8\nrun 1\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let out = export(&case.plan(), ExportOptions::default()).unwrap();
    assert!(out.data.contains("\n4 bond types\n"), "{}", out.data);
    assert!(out.data.contains("\nBonds\n\n1 3 1 2\n2 2 2 3\n3 1 3 4\n4 3 1 3\n5 4 1 4\n"), "{}", out.data);
    for block in [
        "bond_coeff 1 harmonic 2.5 1.0\nbond_coeff 2 harmonic 1.5 0.5\nbond_coeff 3 harmonic 2.5 1.2\nbond_coeff 4 harmonic 1.5 0.7\n",
        "fix cellmd_break1 all bond/break 1 1 1.25\nfix cellmd_break3 all bond/break 1 3 1.5\n",
        "bond_coeff 1 harmonic 4.0 1.0\nunfix cellmd_break1\nfix cellmd_break1 all bond/break 1 1 1.25\n\
         bond_coeff 3 harmonic 4.0 1.2\nunfix cellmd_break3\nfix cellmd_break3 all bond/break 1 3 1.5\n",
    ] {
        assert!(out.input.contains(block), "in.lammps lacks\n{block}\n{}", out.input);
    }
    // Without per-bond r0 the numbering is cellmd's.
    let plain = Case::new(&[("t.top", &top.replace(" 1.2\n", "\n").replace(" 0.7\n", "\n")), ("f.ff", ff), ("deck.in", deck)]);
    assert!(export(&plain.plan(), ExportOptions::default()).unwrap().data.contains("\n2 bond types\n"));
}

/// A `custom` external becomes `fix addforce` with −∇E from the symbolic
/// derivatives (its agreement with LAMMPS is the golden case
/// reference/custom/small.in); an energy that reads a periodic coordinate is
/// refused, since LAMMPS' atom-style `x` is wrapped.
#[test]
fn a_custom_external_exports_as_addforce_with_its_gradient() {
    let trap = "external trap all custom \"0.5*k*(x-x0)^2 + f*z\" k 3 x0 0.5 f 0.7\n";
    let out = export(&deck(&trap.replace("(x-x0)^2", "(z-x0)^2")).plan(), ExportOptions::default()).unwrap();
    for line in ["variable x_trap_fx atom \"(-0.0)\"", "fix x_trap g_trap addforce v_x_trap_fx v_x_trap_fy v_x_trap_fz energy v_x_trap_e"] {
        assert!(out.input.lines().any(|l| l == line), "in.lammps lacks `{line}`:\n{}", out.input);
    }
    let periodic = export(&deck(trap).plan(), ExportOptions::default()).unwrap_err();
    assert!(periodic.contains("external `trap` reads `x` on a periodic axis"), "{periodic}");
}
