"""Runs cellmd for a study and reads its thermo CSV: the one home of the
run-and-read block the studies share (tissue_fracture, collagen,
tensegrity_substrate, force_dipole, contractile_lattice, spheroid_spreading,
hertz_locking).

A study script imports it after putting studies/ on sys.path:

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from cellmd_run import run_command, run_deck, thermo_rows
"""

import csv
import subprocess
import sys
import time


def run_command(command):
    """Runs one command (arguments of any type, passed as strings); exits
    with the command and its stderr if it fails, else returns its stdout."""
    command = [str(c) for c in command]
    proc = subprocess.run(command, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"{' '.join(command)}\nexit {proc.returncode}\n{proc.stderr}")
    return proc.stdout


def run_deck(cellmd, deck, out, variables, device=None):
    """`cellmd run DECK -o OUT --quiet --threads 1 --var KEY=VALUE …` (one
    thread: a study runs its points in parallel), with `--device DEVICE`
    when one is given; exits with the command and its stderr if cellmd
    fails, else returns the wall time in seconds."""
    command = [str(cellmd), "run", str(deck), "-o", str(out), "--quiet", "--threads", "1"]
    if device:
        command += ["--device", device]
    for key, value in variables.items():
        command += ["--var", f"{key}={value}"]
    start = time.monotonic()
    run_command(command)
    return time.monotonic() - start


def thermo_rows(path):
    """The rows of a thermo CSV as dicts of floats keyed by column name
    (the `[unit]` cut off), one per step: where several rows share a step
    (a run's first row repeats the previous run's last; a minimize ends on
    the step of the run before it) the last is kept."""
    with open(path, newline="") as f:
        table = list(csv.reader(f))
    header = [h.split("[")[0] for h in table[0]]
    by_step = {}
    for row in table[1:]:
        values = {k: float(v) for k, v in zip(header, row)}
        by_step[values["step"]] = values
    return list(by_step.values())
