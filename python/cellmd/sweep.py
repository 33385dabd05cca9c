"""Parameter sweeps that scale out through existing engines.

A sweep is a task — a function `task(outdir, **point) -> dict` — and a list
of points (dicts of keyword arguments). Each point runs in its own folder
`ROOT/point-NNNN/` and leaves there its outputs and `result.json` (the point
and the task's dict); `gather()` collects them into `ROOT/summary.csv`. The
same sweep runs

* locally across cores: `Sweep.run_local(workers)`, a
  `concurrent.futures.ProcessPoolExecutor` (spawned processes);
* as a Slurm job array: `Sweep.write_slurm()` writes `ROOT/sweep.sbatch`;
  `sbatch` it, and each array task runs `python -m cellmd.sweep task ROOT`,
  which does the point `$SLURM_ARRAY_TASK_ID`; `python -m cellmd.sweep
  gather ROOT` (or `Sweep.load(ROOT).gather()`) then writes the summary.

A task is named so that another process can import it: a callable defined at
the top level of a module (or of a script, whose top-level code must then sit
under `if __name__ == "__main__":`), or a string `"module:function"` or
`"path/to/file.py:function"`. `Sweep.of_deck` sweeps a deck's variables with
the built-in task `run_deck_point` (the deck runs as `cellmd run -o POINTDIR
--var NAME=VALUE …` would; the result is the point and its last thermo row).

    from cellmd.sweep import Sweep
    sweep = Sweep.of_deck("inputs/catch_slip_sweep.in", [{"steps": n} for n in (1000, 2000)], "out/sweep")
    rows = sweep.run_local(workers=2)
"""

from __future__ import annotations

import argparse
import csv
import importlib
import importlib.util
import json
import multiprocessing
import os
import shlex
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

Task = Union[str, Callable[..., Dict[str, Any]]]

__all__ = ["Sweep", "run_deck_point"]


def task_name(task: Task) -> str:
    """The importable name of a task (`module:function` or `file.py:function`)."""
    if isinstance(task, str):
        return task
    module = getattr(task, "__module__", None)
    name = getattr(task, "__qualname__", "")
    if not module or "<" in name or "." in name:
        raise ValueError(f"found task {task!r}, expected a function defined at the top level of a module or script")
    if module == "__main__":
        main = sys.modules["__main__"]
        if not getattr(main, "__file__", None):
            raise ValueError("a task defined interactively cannot be run by another process; expected it in a module or script file")
        return f"{os.path.abspath(main.__file__)}:{name}"
    return f"{module}:{name}"


def resolve_task(name: str) -> Callable[..., Dict[str, Any]]:
    """The function a task name denotes."""
    where, sep, function = name.rpartition(":")
    if not sep or not where or not function:
        raise ValueError(f"found task `{name}`, expected `module:function` or `path/to/file.py:function`")
    if where.endswith(".py"):
        spec = importlib.util.spec_from_file_location(f"cellmd_sweep_task_{abs(hash(where))}", where)
        if spec is None or spec.loader is None:
            raise ValueError(f"cannot import `{where}`; expected a Python file")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    else:
        module = importlib.import_module(where)
    try:
        return getattr(module, function)
    except AttributeError:
        raise ValueError(f"found no function `{function}` in `{where}`, expected the task's name") from None


def run_deck_point(outdir: str, deck: str, **vars: Any) -> Dict[str, Any]:
    """The task of `Sweep.of_deck`: runs the whole deck with `vars` (outputs
    in `outdir`) and returns its last thermo row (label → value)."""
    from . import Simulation

    threads = int(os.environ.get("SLURM_CPUS_PER_TASK", "0")) or None
    with Simulation(deck, vars=vars, output_dir=outdir, threads=threads) as sim:
        sim.run_deck()
        return {label: float(column[-1]) for label, column in sim.thermo().items() if len(column)}


class Sweep:
    """A task over points, each run in its own folder under `root`."""

    def __init__(self, task: Task, points: Sequence[Dict[str, Any]], root: Union[str, os.PathLike]):
        self.task = task_name(task)
        self.points = [dict(p) for p in points]
        self.root = Path(root).absolute()
        if not self.points:
            raise ValueError("a sweep needs at least one point")

    @classmethod
    def of_deck(cls, deck: Union[str, os.PathLike], points: Sequence[Dict[str, Any]], root: Union[str, os.PathLike]) -> "Sweep":
        """A sweep of a deck's variables: each point is `{NAME: VALUE, …}`."""
        deck = str(Path(deck).absolute())
        return cls("cellmd.sweep:run_deck_point", [{"deck": deck, **p} for p in points], root)

    @classmethod
    def load(cls, root: Union[str, os.PathLike]) -> "Sweep":
        """The sweep saved in `root/sweep.json`."""
        spec = json.loads((Path(root) / "sweep.json").read_text())
        return cls(spec["task"], spec["points"], root)

    def save(self) -> Path:
        """Writes `root/sweep.json` (what a worker or array task reads)."""
        self.root.mkdir(parents=True, exist_ok=True)
        path = self.root / "sweep.json"
        path.write_text(json.dumps({"task": self.task, "points": self.points}, indent=1))
        return path

    def point_dir(self, index: int) -> Path:
        return self.root / f"point-{index:04d}"

    def run_point(self, index: int) -> Dict[str, Any]:
        """Runs one point in its folder; writes and returns its result row."""
        if not 0 <= index < len(self.points):
            raise IndexError(f"found point {index}, expected 0 … {len(self.points) - 1}")
        outdir = self.point_dir(index)
        outdir.mkdir(parents=True, exist_ok=True)
        point = self.points[index]
        measured = resolve_task(self.task)(str(outdir), **point)
        row = {"point": index, **{k: v for k, v in point.items() if k != "deck"}, **measured}
        (outdir / "result.json").write_text(json.dumps(row, indent=1))
        return row

    def run_local(self, workers: Optional[int] = None, threads_per_point: int = 1) -> List[Dict[str, Any]]:
        """Runs every point across `workers` processes (default: the
        number of cores), each with `threads_per_point` threads, then gathers."""
        self.save()
        workers = workers or os.cpu_count() or 1
        # Spawned, not forked: a forked child would inherit the engine's thread pool half-copied.
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_worker_init, initargs=(threads_per_point,)) as pool:
            list(pool.map(_run_saved_point, [str(self.root)] * len(self.points), range(len(self.points))))
        return self.gather()

    def write_slurm(
        self,
        job_name: str = "cellmd-sweep",
        time: str = "01:00:00",
        cpus_per_task: int = 1,
        partition: Optional[str] = None,
        python: Optional[str] = None,
        extra: Sequence[str] = (),
    ) -> Path:
        """Writes `root/sweep.sbatch`, a Slurm job array with one task per
        point (`sbatch ROOT/sweep.sbatch`); `extra` adds `#SBATCH` lines."""
        self.save()
        lines = [
            "#!/bin/bash",
            f"#SBATCH --job-name={job_name}",
            f"#SBATCH --array=0-{len(self.points) - 1}",
            f"#SBATCH --time={time}",
            f"#SBATCH --cpus-per-task={cpus_per_task}",
            f"#SBATCH --output={self.root}/slurm-%A_%a.out",
        ]
        if partition:
            lines.append(f"#SBATCH --partition={partition}")
        lines += [f"#SBATCH {line}" for line in extra]
        lines += [
            "# One point per array task; then: python -m cellmd.sweep gather ROOT",
            "set -euo pipefail",
            f"export RAYON_NUM_THREADS=${{SLURM_CPUS_PER_TASK:-{cpus_per_task}}}",
            f"exec {shlex.quote(python or sys.executable)} -m cellmd.sweep task {shlex.quote(str(self.root))}",
        ]
        path = self.root / "sweep.sbatch"
        path.write_text("\n".join(lines) + "\n")
        return path

    def gather(self) -> List[Dict[str, Any]]:
        """Reads every point's `result.json` and writes `root/summary.csv`
        (one row per point, the union of the columns); a point without a
        result is an error naming it."""
        missing = [i for i in range(len(self.points)) if not (self.point_dir(i) / "result.json").exists()]
        if missing:
            raise RuntimeError(f"points without a result: {missing}; expected every point to have run (see {self.root})")
        rows = [json.loads((self.point_dir(i) / "result.json").read_text()) for i in range(len(self.points))]
        columns: List[str] = []
        for row in rows:
            columns += [k for k in row if k not in columns]
        with open(self.root / "summary.csv", "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=columns)
            writer.writeheader()
            writer.writerows(rows)
        return rows


def _worker_init(threads: int) -> None:
    os.environ["RAYON_NUM_THREADS"] = str(threads)


def _run_saved_point(root: str, index: int) -> Dict[str, Any]:
    return Sweep.load(root).run_point(index)


def main(argv: Optional[Sequence[str]] = None) -> int:
    """`python -m cellmd.sweep task ROOT [--index K]` runs one point (K
    defaults to $SLURM_ARRAY_TASK_ID); `python -m cellmd.sweep gather ROOT`
    writes the summary."""
    parser = argparse.ArgumentParser(prog="python -m cellmd.sweep", description=main.__doc__)
    sub = parser.add_subparsers(dest="what", required=True)
    task = sub.add_parser("task", help="run one point of the sweep saved in ROOT")
    task.add_argument("root")
    task.add_argument("--index", type=int, help="the point (default: $SLURM_ARRAY_TASK_ID)")
    gather = sub.add_parser("gather", help="write ROOT/summary.csv from every point's result")
    gather.add_argument("root")
    args = parser.parse_args(argv)
    sweep = Sweep.load(args.root)
    if args.what == "gather":
        rows = sweep.gather()
        print(f"{sweep.root / 'summary.csv'}: {len(rows)} points")
        return 0
    index = args.index
    if index is None:
        if "SLURM_ARRAY_TASK_ID" not in os.environ:
            parser.error("no --index and no $SLURM_ARRAY_TASK_ID; expected one of them")
        index = int(os.environ["SLURM_ARRAY_TASK_ID"])
    row = sweep.run_point(index)
    print(json.dumps(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
