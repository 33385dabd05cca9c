"""`bench/cytosim --smoke`: the harness checked in seconds without Cytosim.

For each system, cut to two fibres and 0.02 s:
- the Cytosim configs (both time steps, `precondition` 0 and 1) are parsed
  back and every number checked against the description: the simulation
  parameters, each fibre's length and placement (its centre and direction
  give back its first point), each clamp, load and crosslink at the right
  fibre, abscissa and position, the step count and frame count;
- the reader of Cytosim's `report fiber:points` output reads back a report
  written in that format from the description's points;
- cellmd runs the decks of the chosen variants [springs-explicit,
  springs-implicit]; its frames must be the right count, start at the
  description's points, and go through the observables and checks (printed,
  not judged: two fibres for 0.02 s are no statistics).
Any mismatch or failed run exits with status 1.
"""

import math
import os
import re

from . import checks, engines, harness, writers
from .systems import SYSTEMS


class Mismatch(Exception):
    pass


def parse_cym(text):
    """Commands of a config as bench/cytosim writes them: [(verb, words, {key: value})]."""
    lines = [line.split("%")[0].strip() for line in text.splitlines()]
    lines = [line for line in lines if line]
    commands, i = [], 0
    while i < len(lines):
        head, _, inline = lines[i].partition("{")
        i += 1
        body = inline.rstrip("}").split(";") if inline else []
        if not inline and i < len(lines) and lines[i] == "{":
            end = lines.index("}", i)
            body, i = lines[i + 1 : end], end + 1
        values = {}
        for item in body:
            key, _, value = item.partition("=")
            if key.strip():
                values[key.strip()] = value.strip()
        words = head.split()
        commands.append((words[0], words[1:], values))
    return commands


def numbers(text):
    return [float(v) for v in re.split(r"[,\s]+", text.strip()) if v]


def close(a, b, what):
    if len(a) != len(b) or any(abs(x - y) > 1e-9 * max(1.0, abs(y)) for x, y in zip(a, b)):
        raise Mismatch(f"{what}: config has {a}, description {b}")


def check_config(system, dt, pc, text):
    commands = parse_cym(text)
    simul = [v for verb, w, v in commands if verb == "set" and w[0] == "simul"][0]
    close([float(simul[k]) for k in ("time_step", "viscosity", "kT", "precondition")], [dt, system.viscosity, system.kT, pc], "set simul")
    fiber = [v for verb, w, v in commands if verb == "set" and w[0] == "fiber"][0]
    close([float(fiber["rigidity"]), float(fiber["segmentation"])] + numbers(fiber["hydrodynamic_radius"]), [system.rigidity, system.segmentation, system.radius, system.cutoff], "set fiber")
    fibres = [v for verb, w, v in commands if verb == "new" and w[0] == "fiber"]
    if len(fibres) != len(system.fibres):
        raise Mismatch(f"{len(fibres)} fibres in the config, {len(system.fibres)} described")
    for k, (values, (start, direction)) in enumerate(zip(fibres, system.fibres)):
        length, centre, d = float(values["length"]), numbers(values["position"]), numbers(values["direction"])
        close([length], [system.length], f"fibre {k + 1} length")
        close([c - 0.5 * length * x for c, x in zip(centre, d)], list(start), f"fibre {k + 1} first point")
        close(d, list(direction), f"fibre {k + 1} direction")
    singles = [(w[1], v) for verb, w, v in commands if verb == "new" and w[0] == "single"]
    stiffness = {w[1]: float(v["stiffness"]) for verb, w, v in commands if verb == "set" and w[0] == "single"}
    if len(singles) != len(system.clamps) + len(system.loads):
        raise Mismatch(f"{len(singles)} singles, {len(system.clamps)} clamps + {len(system.loads)} loads described")
    for (name, values), (fibre, point) in zip(singles, system.clamps):
        close(numbers(values["position"]), list(system.point(fibre, point)), f"clamp at fibre {fibre + 1} point {point}")
        close(numbers(values["attach"]), [fibre + 1, point * system.segmentation], "clamp attachment")
    for (name, values), (fibre, point, force) in zip(singles[len(system.clamps) :], system.loads):
        pull = [(a - p) * stiffness[name] for a, p in zip(numbers(values["position"]), system.point(fibre, point))]
        close(pull, list(force), f"load on fibre {fibre + 1} point {point} (stiffness × stretch)")
        close(numbers(values["attach"]), [fibre + 1, point * system.segmentation], "load attachment")
    couples = [v for verb, w, v in commands if verb == "new" and w[0] == "couple"]
    if len(couples) != len(system.links):
        raise Mismatch(f"{len(couples)} couples, {len(system.links)} links described")
    for values, (a, i, b, j) in zip(couples, system.links):
        close(numbers(values["attach1"]) + numbers(values["attach2"]), [a + 1, i * system.segmentation, b + 1, j * system.segmentation], "crosslink")
    for verb, words, values in commands:
        if verb == "new" and words[0] != "space" and values.get("placement") != "anywhere":
            raise Mismatch(f"`new {' '.join(words)}` without `placement = anywhere`: Cytosim drops an object it cannot place inside its space")
    run = [(w, v) for verb, w, v in commands if verb == "run"][0]
    close([float(run[0][0]) * dt, float(run[1]["nb_frames"])], [system.time, round(system.time / system.frame)], "run steps × dt, frames")


def check_checker_catches(system):
    """The config check must fail on a config whose last fibre is moved by 1 nm."""
    dt = system.dts[0]
    text = writers.cytosim_config(system, dt, 1)
    head, _, last = text.rpartition("new fiber filament { length = ")
    x = last.split("position = ")[1].split()[0]
    moved = head + "new fiber filament { length = " + last.replace(f"position = {x}", f"position = {float(x) + 1e-3!r}", 1)
    try:
        check_config(system, dt, 1, moved)
    except Mismatch:
        return
    raise Mismatch("the config check passed a config with a fibre moved by 1 nm")


def synthetic_report(system):
    out = ["% frame   0", "% start   0", "% id pos_x pos_y pos_z"]
    for f in range(len(system.fibres)):
        out.append(f"% fiber f1:{f + 1}")
        out += [f" {f + 1} " + " ".join(f"{c:9.6f}" for c in system.point(f, p)) for p in range(system.points)]
    return "\n".join(out + ["% end", ""])


def check_report_reader(system, work):
    """The reader of `report fiber:points`, on a report of the description's points."""
    path = os.path.join(work, "fake_report.sh")
    with open(os.path.join(work, "report.txt"), "w") as f:
        f.write(synthetic_report(system))
    with open(path, "w") as f:
        f.write(f"#!/bin/sh\ncat '{os.path.join(work, 'report.txt')}'\n")
    os.chmod(path, 0o755)
    frames = engines.cytosim_frames(path, work, system.points)
    for f in range(len(system.fibres)):
        for p in range(system.points):
            close(list(frames[0][1][f][p]), list(system.point(f, p)), f"report reader, fibre {f + 1} point {p}")


def run(args, binary):
    variants = args.cellmd_variant.split(",") if args.cellmd_variant_given else ["springs-explicit", "springs-implicit"]
    for name in args.systems.split(","):
        system = SYSTEMS[name]().shrunk(2, 0.02)
        work = os.path.join(args.work, "smoke", name)
        os.makedirs(work, exist_ok=True)
        try:
            for dt in system.dts:
                for pc in (0, 1):
                    check_config(system, dt, pc, writers.cytosim_config(system, dt, pc))
            check_checker_catches(system)
            check_report_reader(system, work)
            results = []
            for variant, scheme, dt in harness.cellmd_runs(system, variants):
                if scheme is None:
                    print(f"{name}: cellmd {variant} not run ({dt})")
                    continue
                deck = writers.write_cellmd(system, variant, dt, os.path.join(work, f"{variant}-dt{dt:g}"))
                try:
                    timing = engines.run_cellmd(binary, deck, args.threads)
                except engines.EngineError as e:
                    raise Mismatch(f"cellmd {variant} dt={dt:g}: {e}")
                frames = engines.cellmd_frames(os.path.dirname(deck), system.points)
                if len(frames) != 3:
                    raise Mismatch(f"cellmd {variant}: {len(frames)} frames, expected 3")
                for f in range(len(system.fibres)):
                    close([c for p in frames[0][1][f] for c in p], [c for p in range(system.points) for c in system.point(f, p)], f"cellmd first frame, fibre {f + 1}")
                results.append((f"cellmd {variant}", scheme, dt, harness.OBSERVE[name](system, frames)))
                print(f"{name}: cellmd {variant} dt={dt:g}: {timing['loop']:.3g} s loop")
            for label, text, ok, z in checks.CHECKS[name](system, results) + checks.cross_checks(system, results):
                print(f"{name}: (not judged) {label}: {text}")
        except Mismatch as e:
            print(f"bench/cytosim --smoke: {name}: {e}")
            return 1
    print("smoke: ok")
    return 0
