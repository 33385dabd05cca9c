"""The Python API (`import cellmd`): decks, commands, runs with callbacks,
state as numpy arrays, errors, builders and the installed `cellmd` command.
Run by scripts/test-all in its test venv (`python -m pytest python/tests`)."""

import math
import re
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import cellmd

REPO = Path(__file__).resolve().parents[2]
DIMER = REPO / "inputs" / "dimer.in"
SINGLE_CELL = REPO / "inputs" / "single_cell.in"
SINGLE_CELL_FF = REPO / "forcefields" / "single_cell.ff"
CATCH_SLIP = REPO / "inputs" / "catch_slip_sweep.in"
QUICKSTART = REPO / "inputs" / "quickstart.in"
NO_GPU = os.environ.get("CELLMD_NO_GPU") == "1"


def dimer(tmp_path, **options):
    return cellmd.Simulation(DIMER, output_dir=tmp_path, **options)


def test_loading_a_deck_applies_its_setup_and_keeps_its_runs(tmp_path):
    sim = dimer(tmp_path)
    assert sim.step == 0 and sim.pending_commands == 1
    assert sim.positions.shape == (2, 3) and sim.forces.shape == (2, 3)
    assert list(sim.ids) == [1, 2] and sim.type_names == ["bead"]
    sim.run(2000)
    assert sim.step == 2000 and math.isclose(sim.time, 2000 * 1e-6)
    thermo = sim.thermo()
    assert list(thermo) == ["step", "time", "pe", "fmax"]
    np.testing.assert_array_equal(thermo["step"], [0, 1000, 2000])
    sim.run_deck()
    assert sim.step == 12000 and sim.pending_commands == 0
    sim.close()
    assert (tmp_path / "dimer.xyz").read_text().count("\n2\n") >= 100


def test_deck_variables_override_the_decks_own(tmp_path):
    sim = cellmd.Simulation(SINGLE_CELL, vars={"steps": 10}, output_dir=tmp_path)
    sim.run_deck()
    assert sim.step == 10


def test_a_run_in_segments_with_a_callback_takes_the_same_steps(tmp_path):
    plain = dimer(tmp_path / "a")
    plain.run(1000)
    seen = []

    def callback(sim):
        seen.append((sim.step, sim.forces.copy()))

    cut = dimer(tmp_path / "b")
    cut.run(1000, callback=callback, every=300)
    assert [s for s, _ in seen] == [300, 600, 900, 1000]
    np.testing.assert_array_equal(plain.positions, cut.positions)
    np.testing.assert_array_equal(plain.thermo()["pe"], cut.thermo()["pe"])


def test_a_callback_returning_false_ends_the_run(tmp_path):
    sim = dimer(tmp_path)
    sim.run(1000, callback=lambda s: s.step < 400, every=200)
    assert sim.step == 400


def test_a_callback_error_propagates_and_the_run_ends(tmp_path):
    sim = dimer(tmp_path)

    def fail(s):
        raise KeyError("from the callback")

    with pytest.raises(KeyError):
        sim.run(100, callback=fail, every=50)
    assert sim.step == 50
    sim.run(10)  # the simulation stays usable
    assert sim.step == 60


def test_a_callback_may_change_parameters_but_not_start_runs(tmp_path):
    sim = dimer(tmp_path)
    sim.command("temperature 0")
    errors, pulls = [], []

    def ramp(s):
        try:
            s.run(1)
        except RuntimeError as e:
            errors.append(str(e))
        pulls.append(s.step)
        s.command(f"external pull all constant_force fz {len(pulls)}")

    sim.run(20, callback=ramp, every=10)
    assert len(errors) == 2 and "inside a run's callback" in errors[0]
    assert pulls == [10, 20] and sim.step == 20
    np.testing.assert_allclose(sim.forces.sum(axis=0)[2], 2 * 2.0, rtol=1e-12)


def test_parameters_change_between_runs(tmp_path):
    sim = dimer(tmp_path)
    pe = sim.thermo_value("pe")
    bond = sim.bond_state()
    assert bond["rest_length"][0] == pytest.approx(0.2)
    sim.command("coeff bond tether r0 0.3")
    assert sim.bond_state()["rest_length"][0] == pytest.approx(0.3)
    assert sim.thermo_value("pe") != pe
    # The tension at the new rest length is k·(r − r0): the bond is now compressed.
    r = np.linalg.norm(sim.positions[1] - sim.positions[0])
    assert sim.bond_state()["tension"][0] == pytest.approx(10 * (r - 0.3))
    sim.command("temperature 0\nexternal pull all constant_force fz 1")
    sim.run(100)
    np.testing.assert_allclose(sim.forces.sum(axis=0)[2], 2.0, rtol=1e-12, atol=0)


def test_positions_can_be_set(tmp_path):
    sim = dimer(tmp_path)
    x = sim.positions
    x[1, 0] += 0.1
    sim.positions = x
    np.testing.assert_array_equal(sim.positions, x)
    r = np.linalg.norm(x[1] - x[0])
    assert sim.bond_state()["length"][0] == pytest.approx(r)
    with pytest.raises(ValueError, match="expected one per particle"):
        sim.positions = np.zeros((3, 3))


def test_thread_counts_give_identical_results(tmp_path):
    runs = []
    for threads in (1, 2):
        sim = cellmd.Simulation(SINGLE_CELL, vars={"steps": 20}, output_dir=tmp_path / str(threads), threads=threads)
        sim.run(20)
        runs.append(sim.positions)
    np.testing.assert_array_equal(runs[0], runs[1])


def test_body_volume_and_area_match_the_thermo_columns(tmp_path):
    sim = cellmd.Simulation(SINGLE_CELL, output_dir=tmp_path)
    bodies = sim.body_state()
    assert sim.body_type_names == ["cell"] and list(bodies["type"]) == [0]
    assert bodies["volume"][0] == pytest.approx(sim.thermo_value("volume/cell"), rel=1e-14)
    assert bodies["area"][0] == pytest.approx(sim.thermo_value("area/cell"), rel=1e-14)
    assert 500 < bodies["volume"][0] < 4 / 3 * math.pi * 5**3


def test_bond_kinetics_state_matches_the_bound_count(tmp_path):
    sim = cellmd.Simulation(CATCH_SLIP, vars={"steps": 2000}, output_dir=tmp_path)
    sim.run_deck()
    state = sim.bond_state()
    types = sim.bond_types
    k = sim.bond_type_names.index("pulled_28pN")
    bound = int(state["bound"][types == k].sum())
    assert bound == sim.thermo_value("nbound/pulled_28pN") < 400
    assert state["bound"].dtype == np.bool_


def test_input_errors_carry_file_line_col(tmp_path):
    bad = REPO / "tests" / "decks" / "bad" / "bad_number.in"
    expected = bad.read_text().splitlines()[0].removeprefix("# expect: ")
    os.chdir(REPO)
    with pytest.raises(cellmd.InputError) as e:
        cellmd.Simulation(Path("tests/decks/bad/bad_number.in"))
    assert str(e.value) == expected
    assert (e.value.path, e.value.line, e.value.col) == ("tests/decks/bad/bad_number.in", 7, 10)
    assert isinstance(e.value, ValueError)


def test_command_and_column_errors_name_their_text(tmp_path):
    sim = dimer(tmp_path)
    with pytest.raises(cellmd.InputError, match=r"^<command 1>:1:12: found bond type `nosuch`"):
        sim.command("coeff bond nosuch k 1")
    with pytest.raises(cellmd.InputError, match=r"^<command 2>:2:1: `topology` changes the system"):
        sim.command("temperature 0\ntopology x.top")
    assert sim.thermo_value("fmax") >= 0  # nothing of the failed texts was applied
    with pytest.raises(cellmd.InputError, match=r"^<column 4>:1:1: found thermo column `nosuch`"):
        sim.thermo_value("nosuch")
    with pytest.raises(cellmd.InputError, match=r"^<column 5>:1:4: found `fmax` after the column name"):
        sim.thermo_value("pe fmax")


def test_blowups_are_run_errors(tmp_path):
    sim = dimer(tmp_path)
    sim.command("timestep 10")
    with pytest.raises(cellmd.RunError, match="blew up at step"):
        sim.run(10)


def test_builder_and_text_assemble_a_system(tmp_path):
    cell = cellmd.build("icosphere", level=1, radius=3.0, no_bonds=True)
    assert cell.counts["particles"] == 42 and cell.counts["bodies"] == 1
    assert "enclosed volume" in cell.summary
    ff = "particle node drag 1\nbody cell surface_tension gamma 10\n"
    deck = "topology cell.top\nforcefield cell.ff\nbox x -9 9 f y -9 9 f z -9 9 f\ntimestep 1e-3\n"
    sim = cellmd.Simulation.from_text(deck, {"cell.top": cell.text, "cell.ff": ff}, directory=tmp_path, output_dir=tmp_path)
    area0 = sim.body_state()["area"][0]
    sim.run(50)
    assert sim.body_state()["area"][0] < area0  # surface tension shrinks it
    with pytest.raises(ValueError, match="--level"):
        cellmd.build("icosphere", levle=1, radius=3.0)
    with pytest.raises(cellmd.InputError) as e:
        cellmd.Simulation.from_text(deck, {"cell.top": cell.text, "cell.ff": "particle node drag 1\nbody cell surface_tension gama 1\n"}, directory=tmp_path / "bad")
    assert e.value.path.endswith("cell.ff") and e.value.line == 2


@pytest.mark.skipif(NO_GPU, reason="CELLMD_NO_GPU=1 (scripts/test-all --no-gpu)")
def test_gpu_device_runs_the_same_system(tmp_path):
    cpu = dimer(tmp_path / "cpu", device="cpu")
    gpu = dimer(tmp_path / "gpu", device="gpu")
    cpu.command("temperature 0")
    gpu.command("temperature 0")
    cpu.run(1000)
    gpu.run(1000, callback=lambda s: None, every=250)
    np.testing.assert_allclose(gpu.positions, cpu.positions, rtol=0, atol=1e-5)


def test_device_gpu_refuses_cpu_only_features(tmp_path):
    # The actin network's `cable` bonds have no device stiffness block.
    sim = cellmd.Simulation(QUICKSTART, output_dir=tmp_path, device="gpu")
    sim.command("integrator implicit")
    with pytest.raises(cellmd.RunError, match="`integrator implicit` with a bond, angle, pair, external or volume-element law that has no GPU stiffness block"):
        sim.run(1)
    assert sim.step == 0


def cellmd_command():
    found = shutil.which("cellmd", path=str(Path(sys.executable).parent))
    assert found, "pip install . puts a `cellmd` command beside the venv's python"
    return found


def test_the_installed_command_line_is_the_executables():
    ok = subprocess.run([cellmd_command(), "check", "inputs/dimer.in"], cwd=REPO, capture_output=True, text=True)
    assert ok.returncode == 0 and "inputs/dimer.in: ok (2 particles, 1 bonds" in ok.stdout
    bad = subprocess.run([cellmd_command(), "check", "tests/decks/bad/bad_number.in"], cwd=REPO, capture_output=True, text=True)
    assert bad.returncode == 1 and "tests/decks/bad/bad_number.in:7:10: found `1e-3x`" in bad.stderr
    listed = subprocess.run([cellmd_command(), "list"], cwd=REPO, capture_output=True, text=True)
    assert listed.returncode == 0 and "turgor" in listed.stdout


def test_both_minimisers_relax_a_cell_to_the_same_state(tmp_path):
    # A level-1 version of inputs/single_cell.in (42 nodes, 20 s here): on this
    # pressurised cell the Newton steps take hundreds of iterations, K̃ dropping
    # much of its Hessian (src/integrate/newton.rs), and the deck's 642 nodes
    # took 424 s in the test venv's unoptimised build. Its first 10 steps leave it off balance; FIRE
    # and damped Newton steps (`style="newton"`) both relax it to
    # max |F| < 1e-6 pN: the same energy (a difference is second order in the
    # residual forces) and the same shape up to the cell's free sliding and
    # turning on its wall (sorted node distances from the centroid).
    cell = cellmd.build("icosphere", level=1, radius=5.0, centre=(0, 0, 5.1))
    volume, area = (float(v) for v in re.search(r"enclosed volume (\S+), area (\S+);", cell.summary).groups())
    edge = float(re.search(r"edge length min \S+ mean (\S+)", cell.summary).group(1))
    ff = SINGLE_CELL_FF.read_text()
    ff = re.sub(r"r0 \S+", f"r0 {edge}", re.sub(r"v0 \S+", f"v0 {volume}", re.sub(r"a0 \S+", f"a0 {area}", ff)))
    deck = SINGLE_CELL.read_text().replace("../topologies/single_cell.top", "cell.top").replace("../forcefields/single_cell.ff", "cell.ff")
    relaxed = []
    for style in ["fire", "newton"]:
        sim = cellmd.Simulation.from_text(deck, {"cell.top": cell.text, "cell.ff": ff}, vars={"steps": 10}, directory=tmp_path, output_dir=tmp_path / style)
        assert len(sim.ids) == 42
        sim.run(10)
        sim.minimize(ftol=1e-6, maxiter=100000, style=style)
        assert sim.minimize_converged
        x = sim.positions
        relaxed.append((sim.thermo_value("pe"), np.sort(np.linalg.norm(x - x.mean(axis=0), axis=1))))
    (e_fire, r_fire), (e_newton, r_newton) = relaxed
    assert abs(e_fire - e_newton) <= 1e-9 * abs(e_fire)
    assert np.abs(r_fire - r_newton).max() < 1e-5
    with pytest.raises(cellmd.InputError, match="found minimize style `cg`"):
        sim.minimize(style="cg")
