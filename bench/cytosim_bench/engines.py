"""Runs each engine on the files `writers` wrote, times it and reads its frames.

A frame is `(time, fibres)` with `fibres[f][p] = (x, y, z)`, the same layout
for both engines. Timing, per run:

- `loop`: the engine's own time for its step loop, start-up and file reading
  left out. cellmd prints `loop time T s` (wall clock). Cytosim's `sim`
  writes a line `F<frame> <time>s CPU <Δ>s <total>s` to messages.cmo at each
  frame (process CPU time, `clock()`); the loop is the CPU time from the first
  frame line to the last, scaled to the whole run's steps (the first frame's
  line also counts the start-up). Cytosim runs on one thread, so on an idle
  machine its CPU time is its wall time.
- `wall` and `cpu`: the whole process (Python's clock; user + system time
  from `os.wait4`), start-up included.
"""

import os
import re
import subprocess
import time


class EngineError(Exception):
    """An engine stopped with an error: the message is its own."""


def timed(command, cwd, env=None):
    start = time.monotonic()
    with open(os.path.join(cwd, "stdout.txt"), "w") as out, open(os.path.join(cwd, "stderr.txt"), "w") as err:
        process = subprocess.Popen(command, cwd=cwd, stdout=out, stderr=err, env=env)
        _, status, usage = os.wait4(process.pid, 0)
    wall = time.monotonic() - start
    code = os.waitstatus_to_exitcode(status)
    process.returncode = code
    text = open(os.path.join(cwd, "stdout.txt")).read()
    errors = open(os.path.join(cwd, "stderr.txt")).read()
    return code, text, errors, wall, usage.ru_utime + usage.ru_stime


# ---------------------------------------------------------------------- cellmd


def run_cellmd(binary, deck, threads):
    work = os.path.dirname(deck)
    code, text, errors, wall, cpu = timed([binary, "run", os.path.basename(deck), "--quiet", "--threads", str(threads), "-o", "."], work)
    if code != 0:
        lines = [line.strip() for line in errors.splitlines() if line.strip()] or [line.strip() for line in text.splitlines() if line.strip()]
        raise EngineError(f"cellmd exit {code}: " + (lines[-1] if lines else "(no message)"))
    loop = float(re.findall(r"loop time ([0-9.e+-]+) s", text)[-1])
    return {"loop": loop, "wall": wall, "cpu": cpu}


def read_xyz(path, points):
    """Frames of a cellmd XYZ dump, particles ordered by id."""
    frames = []
    with open(path) as f:
        while True:
            header = f.readline()
            if not header.strip():
                break
            count = int(header)
            comment = f.readline()
            t = float(re.search(r"Time=(\S+)", comment).group(1))
            positions = {}
            for _ in range(count):
                fields = f.readline().split()
                # species x y z … id: the id is the last column (extended XYZ, src/output/xyz.rs).
                positions[int(fields[-1])] = (float(fields[1]), float(fields[2]), float(fields[3]))
            ids = sorted(positions)
            fibres = [[positions[i] for i in ids[k : k + points]] for k in range(0, len(ids), points)]
            frames.append((t, fibres))
    return frames


def cellmd_frames(work, points):
    return read_xyz(os.path.join(work, "frames.xyz"), points)


# --------------------------------------------------------------------- Cytosim


def run_cytosim(sim, config):
    work = os.path.dirname(config)
    for stale in ("objects.cmo", "properties.cmo", "messages.cmo"):
        if os.path.exists(os.path.join(work, stale)):
            os.remove(os.path.join(work, stale))
    code, text, errors, wall, cpu = timed([sim, os.path.basename(config)], work)
    messages = ""
    if os.path.exists(os.path.join(work, "messages.cmo")):
        messages = open(os.path.join(work, "messages.cmo")).read()
    if code != 0 or "error" in (errors + messages).lower():
        lines = [line for line in (errors + messages + text).splitlines() if line.strip()]
        raise EngineError(f"Cytosim exit {code}: " + " | ".join(lines[-3:]))
    return {"loop": cytosim_loop_time(messages + text), "wall": wall, "cpu": cpu}


def cytosim_loop_time(messages):
    """Cytosim's loop time for its whole run from the frame lines of
    messages.cmo: `F<frame> <simulated time>s CPU <CPU since last frame>s
    <CPU total>s`; the CPU from the first frame to the last, scaled to the
    run's simulated time (the first frame's line also counts the start-up)."""
    rows = [(float(m.group(1)), float(m.group(2))) for m in re.finditer(r"^F\d+\s+([0-9.e+-]+)s\s+CPU\s+([0-9.e+-]+)s", messages, re.M)]
    if len(rows) < 2:
        raise EngineError("Cytosim wrote fewer than two frame lines (F… CPU …) to messages.cmo: cannot time its loop")
    loop_cpu = sum(cpu for _, cpu in rows[1:])
    return loop_cpu * rows[-1][0] / (rows[-1][0] - rows[0][0])


def cytosim_frames(report, work, points):
    """Every frame of objects.cmo, read by Cytosim's own `report fiber:points`."""
    result = subprocess.run([report, "fiber:points", "precision=9"], cwd=work, capture_output=True, text=True)
    if result.returncode != 0:
        raise EngineError(f"Cytosim report exit {result.returncode}: {result.stderr.strip()}")
    frames, fibres, t = [], None, None
    for line in result.stdout.splitlines():
        if line.startswith("% start"):
            t, fibres = float(line.split()[2]), {}
        elif line.startswith("% end"):
            frames.append((t, [fibres[k] for k in sorted(fibres)]))
        elif line.startswith("%") or not line.strip():
            continue
        else:
            fields = line.split()
            fibres.setdefault(int(fields[0]), []).append(tuple(float(v) for v in fields[1:4]))
    for _, fs in frames:
        for points_of in fs:
            if len(points_of) != points:
                raise EngineError(f"Cytosim fibre has {len(points_of)} points, the description {points}")
    return frames


def report_dimension(report):
    """The DIM a Cytosim `report` binary was compiled for (3 is needed)."""
    result = subprocess.run([report, "info"], capture_output=True, text=True)
    m = re.search(r"DIM = (\d)", result.stdout)
    return int(m.group(1)) if m else None
