#!/usr/bin/env python3
"""Tensegrity cell on curved substrates and nano-indentation (seed 003,
Vassaux & Milan 2017), with inputs/tensegrity_substrate.in.

1. Calibration: on a flat substrate, spread the cell (unit stiffness scale)
   until its footprint passes 962 µm², interpolate the total adhesion force
   Σ|f| at 962 µm² between the last two stages, and scale every stiffness by
   47 150 pN / that force (quasi-static: at given adhesion positions every
   force is proportional to the common stiffness scale).
2. Check and indent: the calibrated cell spread on the flat substrate to
   F_sprd = 47.15 nN (its footprint at F_sprd is reported), contracted, then
   indented by a rigid sphere of radius 5 µm; the relaxed load against the travel
   since contact is the force-depth curve.
3. Curvature sweep: the calibrated cell spread to F_sprd on substrates of
   curvature radius ±75, ±150, ±500 µm and flat (the check's own run), then
   contracted; nucleus volumetric and vertical strain, summed stress-fibre
   tension (per fibre, the mean over its cables, summed over fibres) and
   summed cortex-cable tension against 1/R.

Writes OUT/calibration.csv, OUT/indentation.csv, OUT/curvature.csv and, with
plot.py, the PNGs. Not part of CI (tests/suite/tensegrity_substrate.rs runs a
reduced case).

    python3 studies/tensegrity_substrate/sweep.py --cellmd target/release/cellmd --out out/tensegrity_substrate [--level 2] [--device gpu] [--min-style newton] [--jobs 2]

`--min-style newton` relaxes each stage by damped Newton steps (`minimize …
style newton`, sparse Cholesky) instead of FIRE: at level 2 the whole
protocol takes 523 iterations instead of FIRE's 35 488 (4.1 s against 10.0 s);
at level 5 it is slower than FIRE (README, *Dynamics*).
`--jobs N` runs N points at a time (each on one thread); the check runs
beside the curved points, and the flat point reuses it.
The study resumes: a run whose `finished` file names the same variables is
read, not run again, so a long sweep (level 5: 40 min on 2 cores, the
calibration 17 of them; README) can be stopped and started again with the
same command.
"""

import argparse
import concurrent.futures
import csv
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies"))
from cellmd_run import run_command, run_deck, thermo_rows  # noqa: E402

DECK = ROOT / "inputs" / "tensegrity_substrate.in"
F_SPRD = 47150.0  # pN, Vassaux & Milan's total adhesion force at 962 µm²
AREA = 962.0  # µm²
CURVATURES = ["-75", "-150", "-500", "flat", "500", "150", "75"]
FIBRE_SEGMENTS = 3
CENTRE_Z = 11.5  # the cell's centre: its lowest node 1.5 µm above z = 0
GAP = 1.0


def build(cellmd, level, curvature, path):
    """Builds the cell on one substrate; returns the cortex's and the nucleus' volumes and the bottom z."""
    out = run_command(
        [cellmd, "build", "tensegrity", "--radius", "10", "--level", level, "--nucleus", "5",
         "--centre", "0", "0", CENTRE_Z, "--focal-adhesions", "30", "--fibre-segments", FIBRE_SEGMENTS,
         "--bodies", "--seed", "3", "--rest-from-geometry", "--substrate", curvature, "--substrate-extent", "30",
         "-o", path])
    volumes = [float(v) for v in re.findall(r"enclosed volume ([0-9.eE+-]+)", out)]
    bottom = float(re.search(r"touching z = ([0-9.eE+-]+)", out).group(1))
    return volumes[0], volumes[1], bottom


def run(cellmd, top, out, curvature, volumes, level, device=None, **variables):
    """Runs the deck on one topology of `level` (the deck shortens its
    explicit step on finer meshes) on `device` (cpu, gpu or auto; the deck's
    own setting if None); returns the rows of its thermo files, by phase."""
    v_cell, v_nucleus, bottom = volumes
    flat = curvature == "flat"
    values = {"topology": top, "level": level, "v0_cell": v_cell, "v0_nucleus": v_nucleus, "c": 0 if flat else 1,
              "curvature": 0 if flat else float(curvature), "zc": -1000 if flat else bottom + float(curvature)}
    values.update(variables)
    out.mkdir(parents=True, exist_ok=True)
    # A finished run leaves `finished` holding its variables; a second call
    # with the same ones reads its outputs instead of running it again.
    finished = out / "finished"
    said = "".join(f"{k}={values[k]}\n" for k in sorted(values)) + f"device={device}\n"
    if not (finished.exists() and finished.read_text() == said):
        finished.unlink(missing_ok=True)
        run_deck(cellmd, DECK, out, values, device)
        finished.write_text(said)
    phases = {}
    for phase in ["spread", "contract", "indentation"]:
        path = out / f"tensegrity_{phase}.thermo.csv"
        if path.exists():
            # A stage's run and its minimize both end on the same step: the relaxed (last) row is kept.
            phases[phase] = thermo_rows(path)
    return phases


def crossing(rows, key, value, other):
    """`other` interpolated linearly to where `key` first passes `value`
    between two consecutive (relaxed) stages."""
    for a, b in zip(rows, rows[1:]):
        if a[key] < value <= b[key]:
            w = (value - a[key]) / (b[key] - a[key])
            return a[other] + w * (b[other] - a[other])
    raise SystemExit(f"{key} never crossed {value}")


def readouts(phases):
    spread, contract = phases["spread"], phases["contract"]
    first, last = spread[0], contract[-1]
    return {
        "footprint_um2": spread[-1]["hullarea/cortex"],
        "adhesion_force_pN": spread[-1]["fabs/fa"],
        "nucleus_volumetric_strain": last["volume/nucleus"] / first["volume/nucleus"] - 1,
        "nucleus_vertical_strain": last["zspan/nucleus"] / first["zspan/nucleus"] - 1,
        "stress_fibre_force_pN": last["tension/stress_fibre"] / FIBRE_SEGMENTS,
        "cortex_tension_sum_pN": last["tension/edge"],
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--cellmd", default=str(ROOT / "target" / "release" / "cellmd"))
    p.add_argument("--out", default="out/tensegrity_substrate")
    p.add_argument("--level", type=int, default=2)
    p.add_argument("--indent-stages", type=int, default=10)
    p.add_argument("--device", choices=["cpu", "gpu", "auto"], help="cellmd's --device for every run (runs and FIRE relaxations on the GPU)")
    p.add_argument("--min-style", choices=["fire", "newton"], default="fire", help="the deck's minimiser (min_style)")
    p.add_argument("--jobs", type=int, default=1, help="curvature points run at once")
    args = p.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    started = time.time()
    tops = {}
    for curvature in CURVATURES:
        top = out / f"cell_{curvature}.top"
        tops[curvature] = (top, build(args.cellmd, args.level, curvature, top))

    top, volumes = tops["flat"]
    style = {"min_style": args.min_style}
    raw = run(args.cellmd, top, out / "calibrate", "flat", volumes, args.level, args.device, scale=1, spread_area=AREA, steps=0, **style)
    force = crossing(raw["spread"], "hullarea/cortex", AREA, "fabs/fa")
    scale = F_SPRD / force
    print(f"calibration: Σ|f| = {force:.1f} pN at {AREA} µm² with unit stiffnesses; scale {scale:.4f}", file=sys.stderr)

    def check():
        return run(args.cellmd, top, out / "indent", "flat", volumes, args.level, args.device, scale=scale, f_sprd=F_SPRD,
                   indent_stages=args.indent_stages, **style)

    def point(curvature):
        top, volumes = tops[curvature]
        return run(args.cellmd, top, out / f"R_{curvature}", curvature, volumes, args.level, args.device, scale=scale, f_sprd=F_SPRD, **style)

    # The check runs beside the curved points; the flat point is the check's
    # own spreading and contraction (the deck is the same up to the indentation).
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        checking = pool.submit(check)
        curved = {c: pool.submit(point, c) for c in CURVATURES if c != "flat"}
        # A run that fails (a blow-up) stops the sweep: the runs not yet
        # started are cancelled, the one still running is waited for.
        runs = [checking, *curved.values()]
        concurrent.futures.wait(runs, return_when=concurrent.futures.FIRST_EXCEPTION)
        failed = [r.exception() for r in runs if r.done() and not r.cancelled() and r.exception()]
        if failed:
            pool.shutdown(cancel_futures=True)
            raise failed[0]
        checked = checking.result()
        points = [checked if c == "flat" else curved[c].result() for c in CURVATURES]

    area = crossing(checked["spread"], "fabs/fa", F_SPRD, "hullarea/cortex")
    with open(out / "calibration.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["level", "force_at_962_unit_scale_pN", "scale", "footprint_at_F_sprd_um2", "target_um2"])
        w.writerow([args.level, f"{force:.6g}", f"{scale:.6g}", f"{area:.6g}", AREA])
    print(f"check: the calibrated cell reaches {F_SPRD} pN at a footprint of {area:.1f} µm²", file=sys.stderr)

    rows = checked["indentation"]
    # Travel counts from the first relaxed row loaded to 1 pN (the
    # approach's own relaxation may leave the tip free: at level 5 the cell
    # draws back for two stages); after it every relaxed row ends one stage
    # of the deck's indent_step.
    t_contact = next(r["time"] for r in rows if r["load/tip"] >= 1.0)
    indent_step = 0.2  # µm, the deck's default
    with open(out / "indentation.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["travel_um", "load_pN", "depth_um"])
        for n, r in enumerate(r for r in rows if r["time"] >= t_contact):
            w.writerow([f"{n * indent_step:.3f}", f"{r['load/tip']:.6g}", f"{r['depth/tip']:.6g}"])

    with open(out / "curvature.csv", "w", newline="") as f:
        w = None
        for curvature, phases in zip(CURVATURES, points):
            result = {"curvature_um": curvature, "inverse_radius_per_um": 0.0 if curvature == "flat" else 1 / float(curvature)}
            result.update({k: f"{v:.6g}" for k, v in readouts(phases).items()})
            if w is None:
                w = csv.DictWriter(f, fieldnames=list(result))
                w.writeheader()
            w.writerow(result)
            print(f"R = {curvature}: {result}", file=sys.stderr)
    print(f"done in {time.time() - started:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
