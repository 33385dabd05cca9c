"""The full run of bench/cytosim: both engines on one system, the tables."""

import os
import sys

from . import analysis, engines, writers

OBSERVE = {"free": analysis.free_observables, "buckling": analysis.buckling_observables, "bundle": analysis.bundle_observables}


def cellmd_runs(system, variants):
    """(variant, scheme, dt) of each cellmd run, or (variant, None, note) when not run."""
    runs = []
    for variant in variants:
        integrator, constrained = writers.VARIANTS[variant]
        scheme = "implicit" if integrator == "implicit" else "explicit"
        if scheme == "implicit":
            runs += [(variant, scheme, dt) for dt in system.dts]
        else:
            dt = system.explicit_dt.get("constrained" if constrained else "springs")
            if dt == "dts":
                # An inextensible fibre's bending is backward Euler on the
                # explicit step too (integrate::fibre): the implicit predictions apply.
                runs += [(variant, "implicit", dt) for dt in system.dts]
            else:
                runs.append((variant, scheme, dt) if dt else (variant, None, system.explicit_note))
    return runs


def run_system(system, args, binary, table, results):
    work = os.path.join(args.work, system.name)
    points = system.points * len(system.fibres)
    observe = OBSERVE[system.name]
    if args.sim:
        for dt in system.dts:
            for pc in [int(p) for p in args.precondition.split(",")]:
                label = f"Cytosim pc={pc}"
                where = os.path.join(work, f"cytosim-dt{dt:g}-pc{pc}")
                config = writers.write_cytosim(system, dt, pc, where)
                try:
                    timing = engines.run_cytosim(args.sim, config)
                    frames = engines.cytosim_frames(args.report, where, system.points)
                    results.append((label, "implicit", dt, observe(system, frames)))
                    table.append((system, label, dt, timing, None))
                except engines.EngineError as e:
                    table.append((system, label, dt, None, str(e)))
                print(f"  {system.name}: {label} dt={dt:g} done", file=sys.stderr)
    for variant, scheme, dt in cellmd_runs(system, args.cellmd_variant.split(",")):
        label = f"cellmd {variant}"
        if scheme is None:
            table.append((system, label, None, None, f"not run: {dt}"))
            continue
        deck = writers.write_cellmd(system, variant, dt, os.path.join(work, f"cellmd-{variant}-dt{dt:g}"))
        try:
            timing = engines.run_cellmd(binary, deck, args.threads)
            frames = engines.cellmd_frames(os.path.dirname(deck), system.points)
            results.append((label, scheme, dt, observe(system, frames)))
            table.append((system, label, dt, timing, None))
        except engines.EngineError as e:
            table.append((system, label, dt, None, str(e)))
        print(f"  {system.name}: {label} dt={dt:g} done", file=sys.stderr)
    return points


def print_timing(table, threads):
    """One row per run; the ratios are cellmd over Cytosim (pc=0 / pc=1) at
    the same dt (an explicit run: Cytosim's smallest dt), for the same
    simulated time, on the engines' loop times and on the processes' CPU."""
    print("\n| system | engine | dt (s) | steps | loop time (s) | per step (ms) | per point-step (µs) | process CPU (s) | wall (s) | loop ratio pc=0 / pc=1 | CPU ratio pc=0 / pc=1 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    cyto = {}
    for system, label, dt, timing, _ in table:
        if timing and label.startswith("Cytosim"):
            cyto[(system.name, dt, label[-1])] = timing
    for system, label, dt, timing, error in table:
        name = system.label.split(" ")[0]
        if timing is None:
            print(f"| {name} | {label} | {dt if dt is not None else '—'} | — | — | — | — | — | — | — | {error} |")
            continue
        steps = system.steps(dt)
        point_steps = steps * system.points * len(system.fibres)
        ratios = {"loop": [], "cpu": []}
        for pc in "01":
            ref = cyto.get((system.name, dt, pc)) or cyto.get((system.name, min(system.dts), pc))
            for key in ratios:
                ratios[key].append(f"{timing[key] / ref[key]:.3g}" if ref and not label.startswith("Cytosim") else "—")
        engine = label if label.startswith("Cytosim") else f"{label} ({threads} thread{'s' if threads > 1 else ''})"
        print(f"| {name} | {engine} | {dt:g} | {steps} | {timing['loop']:.4g} | {timing['loop'] / steps * 1e3:.4g} | {timing['loop'] / point_steps * 1e6:.4g} | {timing['cpu']:.4g} | {timing['wall']:.4g} | {' / '.join(ratios['loop'])} | {' / '.join(ratios['cpu'])} |")


def print_checks(rows):
    print("\n| run | check | |Δ|/σ | result |")
    print("|---|---|---|---|")
    failed = 0
    for label, text, ok, z in rows:
        failed += not ok
        print(f"| {label} | {text} | {z:.2f} | {'ok' if ok else 'FAIL'} |")
    return failed
