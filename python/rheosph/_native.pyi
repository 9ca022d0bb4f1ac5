"""The compiled part of rheosph (a pyo3 extension); use the functions of ``rheosph`` instead."""

from os import PathLike
from typing import Callable, Optional, Union

_Path = Union[str, PathLike[str]]

__version__: str

class CaseError(ValueError):
    """A case that does not validate; the message is the command line's one line."""

def toml_from_json(json: str) -> str:
    """A case given as a JSON object, written as TOML."""

def check(text: str, file: str, name: str, overrides: list[str]) -> str:
    """Validates a case (TOML text) with `key=value` overrides; its derived values as JSON."""

def run(
    text: str,
    file: str,
    name: str,
    overrides: list[str],
    out: _Path,
    progress: Optional[Callable[[float, float], object]] = None,
    figure_format: Optional[str] = None,
    snapshots: bool = False,
    from_dir: Optional[_Path] = None,
) -> int:
    """Runs a case into `out`: 0 finished, 3 broke down (a result, recorded in summary.json)."""

def particles(run_dir: _Path) -> list[tuple[str, bytes]]:
    """The final state's particle fields: (name, little-endian f64 bytes) pairs."""

def grid_fields(
    run_dir: _Path, spacing: Optional[float] = None
) -> tuple[
    tuple[float, float], tuple[float, float], tuple[int, int], list[tuple[str, bytes]]
]:
    """The final state on a regular grid: (origin, spacing, dims, fields); spacing defaults
    to the particle spacing."""

def cli(argv: list[str]) -> int:
    """Runs the command line with `argv` (argv[0] is the program name); its exit code."""

class LiveRun:
    """A run held in memory and stepped from Python (see ``rheosph.Simulation``)."""

    def __init__(
        self,
        text: str,
        file: str,
        name: str,
        overrides: list[str],
        out: _Path,
        snapshots: bool = False,
    ) -> None: ...
    @staticmethod
    def resume(out: _Path, snapshots: bool = False) -> "LiveRun":
        """The run checkpointed in `out`."""
    def step(self) -> bool:
        """One step; False when the run is over."""
    def advance(
        self, t: float, progress: Optional[Callable[[float, float], object]] = None
    ) -> bool:
        """Steps until the time reaches `t`; Ctrl-C stops between two steps."""
    @property
    def t(self) -> float: ...
    @property
    def dt(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def end_time(self) -> float: ...
    @property
    def breakdown(self) -> Optional[str]: ...
    @property
    def dimension(self) -> int: ...
    def particles(self) -> list[tuple[str, bytes]]:
        """The particle fields now: (name, little-endian f64 bytes) pairs."""
    def set_body_force(self, fx: float, fy: float, fz: Optional[float] = None) -> None: ...
    def set_disc_motion(self, k: int, vx: float, vy: float, spin: float) -> None: ...
    def write_outputs(self, dir: _Path) -> None:
        """series.csv, the probes' files, profile.csv and state.vtu of the state now."""
    def checkpoint(self) -> None:
        """Writes checkpoint.bin now."""
    def finish(self) -> int:
        """Writes the final files: 0 at the end time, 3 broke down, 4 stopped before either."""
