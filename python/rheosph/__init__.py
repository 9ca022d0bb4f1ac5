"""rheosph from Python: incompressible SPH for viscoelastic flows (King & Lind 2021).

Cases are the command line's case files (or dicts of the same keys), validated by the same
code with the same one-line errors; runs write the same run directory; results come back as
numpy arrays.

    import rheosph
    result = rheosph.run("cases/poiseuille.toml", out="runs/p", overrides={"run.end_time": 1.0})
    result.series["t"], result.series["u_centre"]          # series.csv, column by column
    result.summary["errors"]                                # summary.json
    result.particles()["tau_xy"], result.grid().fields["u"] # final state: particles, grid
"""

from __future__ import annotations

import concurrent.futures
import csv
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import CaseError
from ._native import __version__

__all__ = [
    "Case",
    "CaseError",
    "Grid",
    "Result",
    "Simulation",
    "StudyIncomplete",
    "load_case",
    "open_run",
    "rheometry",
    "run",
    "study",
]

CaseLike = Union[str, os.PathLike, Mapping[str, Any], "Case"]


def _override_value(value: Any) -> str:
    """A `--set` value: TOML literals for booleans, numbers and lists; strings as given."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_override_value(v) for v in value) + "]"
    return str(value)


def _overrides(overrides: Optional[Union[Mapping[str, Any], Sequence[str]]]) -> list[str]:
    if overrides is None:
        return []
    if isinstance(overrides, Mapping):
        return [f"{k}={_override_value(v)}" for k, v in overrides.items()]
    return [str(o) for o in overrides]


@dataclass(frozen=True)
class Case:
    """A validated case: its TOML text, the file it came from, its name and overrides.

    `derived` holds the derived numbers (Re, Wi, El, beta, the time-step limits, particles)
    that `rheosph check` prints."""

    text: str
    file: str
    name: str
    overrides: tuple[str, ...] = ()
    derived: dict = field(default_factory=dict)

    def with_overrides(self, overrides) -> "Case":
        """This case with more overrides (later ones win), validated again."""
        extra = tuple(_overrides(overrides))
        return _validated(self.text, self.file, self.name, self.overrides + extra)


def _validated(text: str, file: str, name: str, overrides: Sequence[str]) -> Case:
    derived = json.loads(_native.check(text, file, name, list(overrides)))
    return Case(text, file, name, tuple(overrides), derived)


def load_case(case: CaseLike, overrides=None) -> Case:
    """A case from a file path, a dict of case-file tables (``{"scene": {...}, ...}``) or a
    Case, with overrides (a dict ``{"fluid.beta": 0.2}`` or ``["fluid.beta=0.2"]``).

    Raises CaseError with the command line's one line (file, field, why) if it is invalid."""
    if isinstance(case, Case):
        return case.with_overrides(overrides)
    if isinstance(case, Mapping):
        text = _native.toml_from_json(json.dumps(case))
        return _validated(text, "<dict>", "case", _overrides(overrides))
    path = Path(case)
    try:
        text = path.read_text()
    except OSError as e:
        raise CaseError(f"{path}: cannot read: {e}") from None
    return _validated(text, str(path), path.stem, _overrides(overrides))


def _read_csv(path: Path) -> dict[str, np.ndarray]:
    """A CSV with a header row as {column: array}; numeric columns as float arrays."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    columns: dict[str, np.ndarray] = {}
    for k, name in enumerate(header):
        values = [r[k] if k < len(r) else "" for r in body]
        try:
            columns[name] = np.array([float(v) if v != "" else np.nan for v in values])
        except ValueError:
            columns[name] = np.array(values, dtype=object)
    return columns


@dataclass
class Grid:
    """Fields on a regular grid of cell-centred nodes: `x` (nx,), `y` (ny,), and `fields`
    {name: array (ny, nx)} with NaN outside the fluid; `fields["fluid"]` is 1 inside."""

    x: np.ndarray
    y: np.ndarray
    fields: dict[str, np.ndarray]


class Result:
    """A run directory, read lazily: `series` (series.csv), `summary` (summary.json),
    `profile` (profile.csv), `particles()` and `grid()` (the final state)."""

    def __init__(self, path: Union[str, os.PathLike], exit_code: Optional[int] = None):
        self.path = Path(path)
        self.exit_code = exit_code
        self._series = None
        self._summary = None

    def __repr__(self) -> str:
        return f"Result({str(self.path)!r}, outcome={self.outcome!r})"

    @property
    def series(self) -> dict[str, np.ndarray]:
        """series.csv: {column: array}, one entry per output interval."""
        if self._series is None:
            self._series = _read_csv(self.path / "series.csv")
        return self._series

    @property
    def summary(self) -> dict:
        """summary.json (absent while a run is in progress or if it was killed)."""
        if self._summary is None:
            self._summary = json.loads((self.path / "summary.json").read_text())
        return self._summary

    @property
    def outcome(self) -> Optional[str]:
        """"finished" or "broke_down" (None without a summary)."""
        try:
            return self.summary["outcome"]
        except FileNotFoundError:
            return None

    @property
    def profile(self) -> dict[str, np.ndarray]:
        """profile.csv: every particle at the end with the analytic values at its height."""
        return _read_csv(self.path / "profile.csv")

    def csv(self, name: str) -> dict[str, np.ndarray]:
        """Any CSV of the run directory by file name (drop.csv, centreline.csv, ...)."""
        return _read_csv(self.path / name)

    def particles(self) -> dict[str, np.ndarray]:
        """The final state's particles: x, y, u, v, pressure, tau_xx, tau_xy, tau_yy,
        trace_A, det_A (arrays of one value per particle); for a 3D run x, y, z, u, v, w,
        pressure, the six tau_ab, the six A_ab (viscoelastic), trace_A and det_A."""
        return {
            name: np.frombuffer(data, dtype="<f8").copy()
            for name, data in _native.particles(str(self.path))
        }

    def grid(self, spacing: Optional[float] = None) -> Grid:
        """The final state on a grid (as in the .vti snapshots), nodes `spacing` apart
        (default: the particle spacing)."""
        origin, step, (nx, ny), fields = _native.grid_fields(str(self.path), spacing)
        x = origin[0] + step[0] * np.arange(nx)
        y = origin[1] + step[1] * np.arange(ny)
        arrays = {
            name: np.frombuffer(data, dtype="<f8").reshape(ny, nx).copy()
            for name, data in fields
        }
        return Grid(x, y, arrays)


def open_run(path: Union[str, os.PathLike]) -> Result:
    """A finished (or running) run directory."""
    path = Path(path)
    if not (path / "series.csv").exists():
        raise FileNotFoundError(f"{path} is not a run directory (no series.csv)")
    return Result(path)


def run(
    case: CaseLike,
    out: Optional[Union[str, os.PathLike]] = None,
    overrides=None,
    progress: Optional[Callable[[float, float], Any]] = None,
    figure_format: Optional[str] = "png",
    snapshots: bool = False,
    from_run: Optional[Union[str, os.PathLike, Result]] = None,
) -> Result:
    """Runs a case to its end time (or breakdown) and returns its Result.

    `out` defaults to runs/<case name>; `progress(t, end_time)` is called at every series
    row; `figure_format` is "png", "svg" or None (no charts); `snapshots` writes the .vtu and
    .vti snapshots; `from_run` starts from that finished run's final state (continuation:
    a Wi ramp, a changed parameter), as `rheosph run --from`. A run that breaks down is a
    result: `result.outcome == "broke_down"` and `result.summary["reason"]` says why."""
    c = load_case(case, overrides)
    out = Path(out) if out is not None else Path("runs") / c.name
    if isinstance(from_run, Result):
        from_run = from_run.path
    code = _native.run(
        c.text,
        c.file,
        c.name,
        list(c.overrides),
        str(out),
        progress,
        figure_format,
        snapshots,
        None if from_run is None else str(from_run),
    )
    return Result(out, code)


class Simulation:
    """A live simulation: the command line's run loop, stepped from Python.

    ``sim = Simulation("cases/poiseuille.toml", out="runs/live", overrides={...})`` sets the
    case up and writes the first series row; ``sim.step()`` takes one step,
    ``sim.advance(t)`` steps until the time reaches ``t`` (Ctrl-C stops between two steps,
    leaving the simulation usable). ``sim.t``, ``sim.dt``, ``sim.steps``; ``sim.particles()``
    the fields now as numpy arrays; ``sim.checkpoint()`` then ``Simulation.resume(out)``
    continue bit for bit; ``sim.finish()`` writes the final files and returns the
    :class:`Result`. Steps and outputs are the command line's own: stepped to its end time,
    the run directory holds the same numbers as ``rheosph run``."""

    def __init__(
        self,
        case: CaseLike,
        out: Optional[Union[str, os.PathLike]] = None,
        overrides=None,
        snapshots: bool = False,
        _native_run: Any = None,
    ):
        if _native_run is not None:
            self._run, self.path = _native_run, Path(out)
            return
        c = load_case(case, overrides)
        self.path = Path(out) if out is not None else Path("runs") / c.name
        self._run = _native.LiveRun(
            c.text, c.file, c.name, list(c.overrides), str(self.path), snapshots
        )

    @classmethod
    def resume(cls, out: Union[str, os.PathLike], snapshots: bool = False) -> "Simulation":
        """The simulation checkpointed in ``out`` (by ``checkpoint()`` or a run's cadence)."""
        return cls(None, out, _native_run=_native.LiveRun.resume(str(out), snapshots))

    def step(self) -> bool:
        """One step; False once the run is at its end time or has broken down."""
        return self._run.step()

    def advance(
        self, t: float, progress: Optional[Callable[[float, float], Any]] = None
    ) -> bool:
        """Steps until the time reaches ``t`` (whole steps: the last may pass it), the end
        time or a breakdown; ``progress(t_now, t)`` after every step. False once over."""
        return self._run.advance(t, progress)

    @property
    def t(self) -> float:
        return self._run.t

    @property
    def dt(self) -> float:
        """The last step's size (0 before the first)."""
        return self._run.dt

    @property
    def steps(self) -> int:
        return self._run.steps

    @property
    def end_time(self) -> float:
        return self._run.end_time

    @property
    def breakdown(self) -> Optional[str]:
        """Why the run broke down, or None."""
        return self._run.breakdown

    @property
    def dimension(self) -> int:
        """2 or 3 (the case's ``scene.dimension``)."""
        return self._run.dimension

    def particles(self) -> dict[str, np.ndarray]:
        """The particles now: x, y, u, v, pressure, vorticity, tau_xx, tau_xy, tau_yy,
        trace_A, det_A; for a viscoelastic fluid A_xx, A_xy, A_yy; in a free-surface scene
        after its first step, free_surface and near_surface (1.0 for the particles the last
        step found on, or next to, the surface; 0.0 otherwise). In 3D: x, y, z, u, v, w,
        pressure, the six tau_ab and, viscoelastic, the six A_ab, trace_A and det_A. Every
        particle here is fluid: walls and discs are represented by mirrors, which are not
        particles of the state."""
        return {
            name: np.frombuffer(data, dtype="<f8").copy() for name, data in self._run.particles()
        }

    def set_body_force(self, fx: float, fy: float, fz: Optional[float] = None) -> None:
        """The body force per unit mass for the steps that follow (a case's
        ``scene.body_force``); ``fz`` in 3D only."""
        self._run.set_body_force(float(fx), float(fy), None if fz is None else float(fz))

    def set_disc_motion(self, k: int, velocity: Sequence[float], spin: float = 0.0) -> None:
        """Steers prescribed disc ``k`` (``scene.discs[k]``): its velocity ``(vx, vy)`` and
        spin for the steps that follow, as if the case had given them. A disc the fluid moves
        (``free``, ``free-rotation``) or one in the Eulerian frame raises :class:`CaseError`."""
        vx, vy = (float(v) for v in velocity)
        self._run.set_disc_motion(int(k), vx, vy, float(spin))

    def write_outputs(self, directory: Union[str, os.PathLike]) -> None:
        """Writes the usual files of the state now into ``directory`` (created if missing),
        the simulation going on: series.csv so far and the probes' files, profile.csv at the
        current time (with the analytic columns where the scene has a reference), and the
        particles as state.vtu (for ParaView)."""
        self._run.write_outputs(str(directory))

    def checkpoint(self) -> None:
        """Writes ``checkpoint.bin`` in the run directory now."""
        self._run.checkpoint()

    def finish(self) -> "Result":
        """Writes the final files (series, profile, charts, summary.json) and ends the
        simulation. A simulation stopped before its end time is recorded as finished at the
        time it reached."""
        code = self._run.finish()
        return Result(self.path, 0 if code == 4 else code)


def _cli(argv: list[str]) -> int:
    code = _native.cli(["rheosph", "--quiet", *argv])
    if code not in (0, 3):
        raise RuntimeError(f"rheosph {' '.join(argv)} failed (exit code {code}); see stderr")
    return code


class StudyIncomplete(RuntimeError):
    """Members of a study that did not finish on its executor (an exception, a lost worker).

    ``failed`` maps each member's run directory (relative to the study's) to what went wrong.
    The study's table is written all the same, at ``table``: the finished members' rows, and
    a row whose ``outcome`` is ``lost`` (not run, or its worker lost) or ``failed`` (its run
    stopped on an error) for each other member. Calling :func:`study` again with the same
    arguments and ``out`` runs only these: finished members are read back, not rerun."""

    def __init__(self, out: str, failed: dict[str, str], table: Optional[Path] = None):
        self.out = out
        self.failed = failed
        self.table = table
        lines = "\n  ".join(f"{m}: {why}" for m, why in sorted(failed.items()))
        written = f"the table, with a row for each, is {table}\n" if table else ""
        super().__init__(
            f"{len(failed)} members of the study in {out} did not finish:\n  {lines}\n"
            f"{written}call study() again with the same arguments to run only these"
        )


def _run_member(directory: str) -> int:
    """Runs one emitted member (its ``case.toml``) into its own directory, unless finished.

    Top level, so that process pools and cluster executors can pickle it."""
    d = Path(directory)
    if (d / "summary.json").exists():
        return 0
    return _cli(["run", str(d / "case.toml"), "--out", str(d), "--no-snapshots", "--no-charts"])


def study(
    kind: str,
    case: Union[str, os.PathLike],
    out: Union[str, os.PathLike],
    overrides=None,
    executor: Optional["concurrent.futures.Executor"] = None,
    **options: Any,
) -> dict[str, np.ndarray]:
    """Runs a study as `rheosph study <kind>` does and returns its table as arrays.

    kind: "convergence", "stability", "speed-accuracy" or "cylinder"; options are the
    command's flags with underscores, lists for comma lists, e.g.
    ``study("convergence", "cases/poiseuille.toml", "runs/conv", resolutions=[15, 30])``;
    ``vary={"scheme.viscosity": ["explicit", "implicit"]}`` for --vary.

    executor: any :class:`concurrent.futures.Executor` (a process pool, dask.distributed's
    ``Client.get_executor()``, ``mpi4py.futures.MPIPoolExecutor``, submitit's executor). The
    study's members are written first (``--emit``), each is run where the executor puts it,
    then the table and charts are assembled from them (``--collect``), with the same numbers
    as a study run here. A member that raises or is lost is a ``lost`` or ``failed`` row of
    the table, and is reported in :class:`StudyIncomplete` (raised once the table is
    written); calling again completes only what is missing. Without an
    executor the study runs in this process (``jobs=N`` runs N members at a time); a member
    whose run fails is a ``failed`` row, the others go on, and :class:`StudyIncomplete` is
    raised once the table is written (``reuse=True`` then runs only the failed ones)."""
    argv = ["study", kind, str(case)]
    for o in _overrides(overrides):
        argv += ["--set", o]
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if key == "vary":
            for k, values in value.items():
                argv += [flag, f"{k}=" + ",".join(_override_value(v) for v in values)]
        elif isinstance(value, bool):
            argv += [flag] if value else []
        elif isinstance(value, (list, tuple)):
            argv += [flag, ",".join(str(v) for v in value)]
        else:
            argv += [flag, str(value)]
    if executor is None:
        _run_here(argv, Path(out))
    else:
        _run_elsewhere(argv, Path(out), executor)
    table = _TABLES.get(kind)
    return _read_csv(Path(out) / table) if table else {}


# Each study's table, and the exit code of `--collect` that wrote it with members missing.
_TABLES = {
    "convergence": "convergence.csv",
    "stability": "stability.csv",
    "speed-accuracy": "speed_accuracy.csv",
    "cylinder": "cylinder.csv",
}
_EXIT_INCOMPLETE = 4


def _run_here(argv: list[str], out: Path) -> None:
    """Runs the study in this process; a member that failed raises :class:`StudyIncomplete`
    once the table is written (its error is in its run directory's ``error.txt``)."""
    here = argv + ["--out", str(out)]
    code = _native.cli(["rheosph", "--quiet", *here])
    if code == _EXIT_INCOMPLETE:
        failed = {
            str(e.parent.relative_to(out)): e.read_text().strip()
            for e in sorted(out.glob("runs/*/error.txt"))
        }
        raise StudyIncomplete(str(out), failed, out / _TABLES[argv[1]])
    if code not in (0, 3):
        raise RuntimeError(f"rheosph {' '.join(here)} failed (exit code {code}); see stderr")


def _run_elsewhere(argv: list[str], out: Path, executor: Any) -> None:
    """Emits the study's members, runs each on `executor`, and collects the study."""
    _cli(argv + ["--emit", str(out)])
    members = (out / "members.txt").read_text().split()
    futures = {m: executor.submit(_run_member, str(out / m)) for m in members}
    failed: dict[str, str] = {}
    for member, future in futures.items():
        try:
            future.result()
        except Exception as e:  # a lost worker surfaces here as the executor's own error
            failed[member] = f"{type(e).__name__}: {e}"
    # Collect in any case: the table then holds the finished members and a row for each
    # missing one.
    collect = argv + ["--collect", str(out)]
    code = _native.cli(["rheosph", "--quiet", *collect])
    if code == _EXIT_INCOMPLETE:
        raise StudyIncomplete(str(out), failed, out / _TABLES[argv[1]])
    if code not in (0, 3):
        raise RuntimeError(f"rheosph {' '.join(collect)} failed (exit code {code}); see stderr")


def rheometry(
    case: Union[str, os.PathLike], out: Union[str, os.PathLike], overrides=None
) -> dict[str, dict[str, np.ndarray]]:
    """The case's fluid in homogeneous flows (`rheosph rheometry`): {"steady_shear": ...,
    "startup_shear": ..., "planar_extension": ..., "saos": ...}, each {column: array}."""
    argv = ["rheometry", str(case), "--out", str(out)]
    for o in _overrides(overrides):
        argv += ["--set", o]
    _cli(argv)
    return {
        name: _read_csv(Path(out) / f"{name}.csv")
        for name in ("steady_shear", "startup_shear", "planar_extension", "saos")
        if (Path(out) / f"{name}.csv").exists()
    }
