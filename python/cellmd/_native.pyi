"""Types of cellmd's native module (python/src/lib.rs); use it through `cellmd`."""

import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

class InputError(ValueError):
    """A bad deck, topology, force field or command: `file:line:col: found …, expected …`."""

    path: str
    line: int
    col: int
    message: str

class RunError(RuntimeError):
    """A run that stopped: a blow-up (with its diagnosis), an output error, a refused backend."""

class Simulation:
    """A live simulation set up by a deck (see `cellmd.Simulation`)."""

    def __init__(
        self,
        deck: Union[str, os.PathLike],
        vars: Optional[Mapping[str, Any]] = None,
        output_dir: Union[str, os.PathLike, None] = None,
        device: Optional[str] = None,
        threads: Optional[int] = None,
        echo: bool = False,
    ) -> None: ...
    def run_deck(self) -> None:
        """Applies the deck's remaining commands (its runs and what follows them)."""
    @property
    def pending_commands(self) -> int:
        """The number of the deck's commands not yet applied."""
    def command(self, text: str) -> None:
        """Executes deck lines against the live system, validated in the deck's context."""
    def run(self, steps: int, callback: Optional[Callable[["Simulation"], Optional[bool]]] = None, every: Optional[int] = None) -> None:
        """Runs `steps` steps, calling `callback(sim)` at multiples of `every` (False stops the run)."""
    def minimize(self, ftol: Optional[float] = None, maxiter: Optional[int] = None, dmax: Optional[float] = None, style: Optional[str] = None) -> None:
        """Energy minimisation, FIRE or (style="newton") damped Newton steps; the step counter does not advance."""
    @property
    def minimize_converged(self) -> Optional[bool]:
        """Whether the last minimisation converged (None before any)."""
    @property
    def step(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def ids(self) -> npt.NDArray[np.uint64]:
        """Particle ids, in the row order of every per-particle array."""
    @property
    def types(self) -> npt.NDArray[np.uint32]: ...
    @property
    def type_names(self) -> List[str]: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """N×3, wrapped into the box; assignable (image counters kept)."""
    @positions.setter
    def positions(self, value: npt.ArrayLike) -> None: ...
    @property
    def images(self) -> npt.NDArray[np.int64]:
        """N×3 periodic image counters."""
    @property
    def unwrapped_positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def forces(self) -> npt.NDArray[np.float64]:
        """N×3 forces at the current positions."""
    @property
    def bonds(self) -> npt.NDArray[np.uint32]:
        """M×2 particle rows of every bond."""
    @property
    def bond_types(self) -> npt.NDArray[np.uint32]: ...
    @property
    def bond_type_names(self) -> List[str]: ...
    def bond_state(self) -> Dict[str, npt.NDArray[Any]]:
        """Arrays over the bonds: bound, tension, length, rest_length."""
    def body_state(self) -> Dict[str, npt.NDArray[Any]]:
        """Arrays over the bodies: id, type, volume, area."""
    @property
    def body_type_names(self) -> List[str]: ...
    def thermo(self) -> Dict[str, npt.NDArray[np.float64]]:
        """Thermo rows so far: column label → array over rows."""
    def thermo_value(self, column: str) -> float:
        """One thermo column's value at the current state."""
    def close(self) -> None:
        """Finishes every output file."""
    def __enter__(self) -> "Simulation": ...
    def __exit__(self, *args: Any) -> bool: ...

def build_topology(args: List[str]) -> Tuple[str, str, Dict[str, int]]:
    """A topology generator with `cellmd build`'s arguments: (text, summary, counts)."""

def cli_main(args: List[str]) -> int:
    """The `cellmd` command line (`args[0]` the program name); its exit status."""

def version() -> str: ...
