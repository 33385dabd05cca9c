"""cellmd from Python: load a deck or assemble a system, run it, read it as numpy arrays.

    import cellmd
    sim = cellmd.Simulation("inputs/single_cell.in", vars={"steps": 2000}, output_dir="out")
    sim.run(2000, callback=lambda s: print(s.step, s.body_state()["volume"]), every=500)
    sim.command("coeff bond edge k 40")     # any deck line, validated against the deck
    sim.minimize(ftol=1e-6)
    sim.thermo()["volume/cell"]              # thermo rows as arrays

A system can also be put together from a builder and force-field text:

    cell = cellmd.build("icosphere", level=2, radius=5.0)
    sim = cellmd.Simulation.from_text(DECK, files={"cell.top": cell.text, "cell.ff": FORCEFIELD})

Bad input raises `cellmd.InputError` (a ValueError) whose text is the
`file:line:col: found …, expected …` message; a run that stops (a blow-up,
an output error) raises `cellmd.RunError` (a RuntimeError). Parameter sweeps
across cores or as a Slurm job array: `cellmd.sweep`.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Optional, Union

from . import _native
from ._native import InputError, RunError

__all__ = ["Simulation", "Built", "build", "InputError", "RunError", "__version__"]
__version__ = _native.version()


class Simulation(_native.Simulation):
    """A live simulation set up by a deck.

    `Simulation(deck, vars=None, output_dir=".", device=None, threads=None, echo=False)`
    validates the deck (`vars` override its `variable` lines, as `cellmd run
    --var`) and applies its commands up to its first `run` or `minimize`;
    `run_deck()` applies the rest. Every per-particle array is in the
    topology's particle order (`ids`).
    """

    #: Holds the temporary folder of `from_text` (removed with the simulation).
    _scratch: Optional[tempfile.TemporaryDirectory] = None

    @classmethod
    def from_text(
        cls,
        deck: str,
        files: Optional[Mapping[str, str]] = None,
        directory: Union[str, os.PathLike, None] = None,
        **options: Any,
    ) -> "Simulation":
        """A simulation from a deck's text and the text of the files it reads.

        `files` maps names (as the deck's `topology` and `forcefield` lines
        give them) to their text, e.g. a `build(...)` result's `.text` and a
        force field. They are written with the deck (`deck.in`) to
        `directory` (default: a temporary folder kept while the simulation
        lives), so error messages name real files and lines. `options` are
        those of `Simulation(...)`; outputs go to `output_dir` (default: the
        working directory).
        """
        scratch = None
        if directory is None:
            scratch = tempfile.TemporaryDirectory(prefix="cellmd-")
            directory = scratch.name
        folder = Path(directory)
        folder.mkdir(parents=True, exist_ok=True)
        for name, text in (files or {}).items():
            path = folder / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
        deck_path = folder / "deck.in"
        deck_path.write_text(deck)
        sim = cls(deck_path, **options)
        sim._scratch = scratch
        return sim


@dataclass
class Built:
    """A generated topology: its text, the summary `cellmd build` prints
    (volume, area and edge lengths of shells, filament stiffness, …) and its counts."""

    text: str
    summary: str
    counts: dict = field(default_factory=dict)

    def write(self, path: Union[str, os.PathLike]) -> Path:
        """Writes the topology file; returns its path."""
        path = Path(path)
        path.write_text(self.text)
        return path


def build(generator: str, **options: Any) -> Built:
    """Runs a topology generator of `cellmd build` (icosphere, filament,
    network, aster, cortex, branched, filopodium, cells, sheet, tensegrity).

    Options are the command line's with `_` for `-`: `build("icosphere",
    level=2, radius=5.0, centre=(0, 0, 5))` is `cellmd build icosphere
    --level 2 --radius 5.0 --centre 0 0 5`; True gives a flag, False or None
    leaves it out; `output=PATH` also writes the file. Bad options raise
    ValueError with the command line's message. See `cellmd build GENERATOR --help` for each generator's options.
    """
    output = options.pop("output", None)
    args = [generator, "--output", str(output or "unused.top")]  # the parser requires one
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple)):
            args += [flag, *map(str, value)]
        else:
            args += [flag, str(value)]
    text, summary, counts = _native.build_topology(args)
    built = Built(text, summary, dict(counts))
    if output is not None:
        built.write(output)
    return built
