"""One sweep point, solved where the executor runs it (a local process or a Dask worker).

:func:`solve_point` is the task function: it receives a :class:`PointTask` (the problem and
the warm start), solves, and returns a :class:`PointOutcome`: the summary row, the finished
gait as plain data in the gait-file schema (``Gait.to_dict()``) and, for the neighbours, the
engine :class:`~gaitopt.ocp.Result` whose values and multipliers warm-start them. The worker
writes nothing: the driver writes the gait file, so a worker needs no access to the sweep
directory (a Dask cluster without a shared filesystem). For the same reason a warm start
from a gait file kept from an earlier run travels as the file's text (:class:`SavedGait`),
read by the driver. Everything in these objects pickles (a task with a Result to start from
is about 13 kB, an outcome about 60 kB).

Transcriptions are cached per process by :mod:`gaitopt.gait.solve.staged`; the outcome says which
problem structures this process has built, so the driver can send a process more points of a
structure it already has.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import socket
import threading
import time
import traceback
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gaitopt.gait.api import guess_from_gait, regridded_point, restart_point
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run
from gaitopt.gait.solve.staged import StagedRun, solve_walking
from gaitopt.gait.solve.stages import MONOTONE_RESTART_STAGE, WARM_START_STAGE
from gaitopt.gait.solve.warm_accuracy import check_point
from gaitopt.ocp import Guess, ProblemError, Result, WarmStart, secant_start
from gaitopt.robot.model import RobotModel
from gaitopt.study.summary import SpeedMode, SummaryRow, failed_row, summary_row, variant_flags

#: How a point started from a gait file of the same problem on another grid (its point and
#: multipliers mapped onto the point's grid, :func:`~gaitopt.gait.api.regridded_point`; the
#: study's check and refinement sweeps with feet). Measured on the seven-link check grid
#: (36 + 24 knots from 24 + 16, 2026-12-03): 17-58 iterations at nine points where the
#: file's values alone took 34-643, and converged at a point where they failed (24 m/min
#: without ankle torques or impulse); the same optima (within 0.003 %). IPOPT restarts there
#: with the warm start's barrier, 1e-6 (:data:`gaitopt.ocp.transcription.WARM_START_OPTIONS`),
#: not the 1e-4 (``REGRID_OPTIONS``) of a solve's own move onto its check grid, which moves
#: from a coarser optimum: at 15 check points (2026-12-04) 8-25 iterations instead of 17-92,
#: the same optima (within 1e-8) at 14 and at 48 m/min with ankle torques the study grid's
#: branch (2621.90, the study grid 2621.97) where 1e-4 moved to a dearer one (2623.13).
#: With the monotone barrier only (not in :data:`ADAPTIVE_STARTS`).
REGRIDDED = "file, regridded"
#: How a chain point started from the secant through its chain's last two Results
#: (:func:`gaitopt.ocp.guess.secant_start`).
SECANT = "result, secant"
#: How a point started from its neighbour's Result as it is (a chain's last point, or the
#: same speed's point of the variant it is carried over from).
RESULT = "result"
#: The starts solved with the adaptive barrier first (``solve_walking(adaptive_restart=
#: True)``, :data:`gaitopt.gait.solve.stages.RESTART_OPTIONS`); every other start with
#: multipliers takes the monotone barrier only. Measured on 2026-12-04
#: (docs/results/benchmarks-gait.md, "The warm start's adaptive barrier"), against the
#: monotone barrier: ``gaitopt study --model seven-link``, the 23 points started from a
#: neighbour's Result, 337 instead of 507 iterations; its 21 secant starts 2,239 instead of
#: 1,602 (three not converged within :data:`~gaitopt.gait.solve.stages.RESTART_MAX_ITER`:
#: a prediction is not a solution, its multipliers need not fit its values); ``gaitopt
#: study --costs --model seven-link``, the speed-free points started from the file of
#: another cost, none converged within the bound (100 iterations more each). On regridded
#: starts the adaptive barrier once ran for minutes.
ADAPTIVE_STARTS = frozenset({RESULT})
#: Problem structures whose transcription this process has built (see module docstring).
_BUILT: set[str] = set()
#: One solve at a time per process: a Dask worker with several threads shares the process's
#: cached transcriptions, which are not meant for concurrent use.
_LOCK = threading.Lock()


@dataclass(frozen=True)
class SavedGait:
    """A gait file's text as the driver read it (``source``: its path there, for messages)."""

    source: str
    text: str

    @classmethod
    def read(cls, path: str | os.PathLike[str]) -> SavedGait:
        """The file's text; an unreadable file gives empty text (the point then starts
        cold, its outcome says ``file unreadable``)."""
        try:
            return cls(str(path), Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError):
            return cls(str(path), "")


@dataclass(frozen=True, kw_only=True)
class PointTask:
    """What a worker needs to solve one point.

    ``warm`` is the finished neighbour's Result (values and multipliers), or its gait file's
    text (a point kept from an earlier run), or None (cold start). ``relfile`` is the gait
    file's path relative to the sub-sweep folder (the summary row's ``file``).
    ``force_fail`` (a testing hook) solves with ``max_iter = 1`` so that the point fails
    through the real solver path. ``check_grid``: a warm-started point also solves its
    check grid (:attr:`gaitopt.study.plan.SweepSpec.check_grid`); ``check_cold``: a cold
    point does (:attr:`gaitopt.study.plan.SweepSpec.check_cold`). ``secant``: with a Result
    ``warm``, the Result before it on the chain and the step ratio: the point starts from
    their secant prediction (:func:`gaitopt.ocp.secant_start`;
    :attr:`gaitopt.study.plan.SweepSpec.secant`).
    """

    key: str
    model: RobotModel
    options: GaitOptions
    variant: str
    speed_mode: SpeedMode
    structure: str
    warm: Result | SavedGait | None
    relfile: str
    force_fail: bool = False
    check_grid: bool = False
    check_cold: bool = True
    secant: tuple[Result, float] | None = None


@dataclass(frozen=True, kw_only=True)
class PointOutcome:
    """What came of one point.

    ``row`` is the summary row (failed rows name the failed stage in ``status``); ``gait``
    the solved gait as plain data in the gait-file schema (``Gait.to_dict()``) for the driver
    to write, None for a failed point (and once written); ``result`` the final engine result
    when the point succeeded (for its neighbours), else None;
    ``warm`` how it started (``result``, ``result, secant`` (the secant prediction through
    its chain's last two Results), ``file`` (its NLP point and multipliers), ``file,
    regridded`` (those of a file on another grid, mapped: :data:`REGRIDDED`), ``file,
    values`` (its trajectories), ``none``, or ``file unreadable``);
    ``fell_back`` whether a warm start failed and the cold path was taken;
    ``iterations`` the IPOPT iterations over all stages; ``worker`` host:pid; ``timings``
    where the time went (s): ``warm_start_s`` (reading a gait file), ``build_and_setup_s``
    (transcription build on a process's first point of a structure, guesses), ``ipopt_s``
    (the stages' solves), ``record_s`` (the gait record and its plain data), and, added by
    the driver, ``write_s`` (the atomic save of the gait file).
    """

    key: str
    row: SummaryRow
    gait: Mapping[str, Any] | None
    result: Result | None
    warm: str
    fell_back: bool
    stages: int
    iterations: int
    wall_time_s: float
    worker: str
    structures: frozenset[str]
    error: str = ""
    timings: Mapping[str, float] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return self.row.success


def worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def _warm_start(task: PointTask) -> tuple[Guess | Result | WarmStart | None, str,
                                         WarmStart | None]:
    """The start of ``task``: its Result; from a gait file the NLP point and multipliers the
    file keeps when they fit the point's transcription (the same grid and problem structure:
    :func:`gaitopt.gait.api.restart_point`; ``file``), else the file's trajectories (``file,
    values``); None (``none``) for a cold start. Third: the file's check-grid point
    (``solver.warm_start_check``, :func:`gaitopt.gait.solve.warm_accuracy.check_point`) for
    the point's check grid (used where it fits), else None."""
    if isinstance(task.warm, Result):
        if task.secant is not None:
            before, ratio = task.secant
            with contextlib.suppress(ProblemError):  # not of one transcription: the Result
                return secant_start(before, task.warm, ratio), SECANT, None
        return task.warm, RESULT, None
    if isinstance(task.warm, SavedGait):
        try:
            gait = Gait.from_dict(json.loads(task.warm.text), source=task.warm.source)
            point = restart_point(task.model, task.options, gait)
            check = check_point(gait) if task.check_grid else None
            if point is not None:
                return point, "file", check
            mapped = regridded_point(task.model, task.options, gait)
            return ((mapped, REGRIDDED, check) if mapped is not None
                    else (guess_from_gait(gait), "file, values", check))
        except (GaitFileError, KeyError, ValueError):
            return None, "file unreadable", None
    return None, "none", None


def failed_point_row(task: PointTask, status: str, *, iterations: int = 0,
            wall_time_s: float = math.nan) -> SummaryRow:
    """The summary row of a point that failed (the requested speed; NaN when free)."""
    ankle, impulse = variant_flags(task.variant)
    speed = task.options.speed if task.options.speed is not None else math.nan
    return failed_row(ankle=ankle, impulse=impulse, speed_mode=task.speed_mode, status=status,
                      speed_m_s=speed, iterations=iterations, wall_time_s=wall_time_s)


def _failure_status(solution: StagedRun) -> str:
    stage = solution.failed_stage
    where = stage.name if stage is not None else "solve"
    return f"failed at {where}: {solution.result.status}"


def solve_point(task: PointTask) -> PointOutcome:
    """Solve one point (see the module docstring). Never raises for a failed solve or an
    error inside it: the outcome's row says failed and why."""
    clock = time.perf_counter
    start = clock()
    with _LOCK:  # a start from a file's NLP point builds (or reuses) the process's transcription
        warm, how, check = _warm_start(task)
    timings = {"warm_start_s": clock() - start}
    options = task.options.replace(max_iter=1) if task.force_fail else task.options
    solution: StagedRun | None = None
    result: Result | None = None
    data: dict[str, Any] | None = None
    error = ""
    try:
        with _LOCK:
            solution = solve_walking(task.model, options, warm_start=warm,
                                     check_warm_start=task.check_grid, check_start=check,
                                     check_cold=task.check_cold or task.check_grid,
                                     adaptive_restart=how in ADAPTIVE_STARTS)
            ipopt = sum(s.wall_time_s for s in solution.stages)
            timings["ipopt_s"] = ipopt
            timings["build_and_setup_s"] = solution.wall_time_s - ipopt
            mark = clock()
            gait = gait_from_run(solution) if solution.success else None
            data = gait.to_dict() if gait is not None else None
            timings["record_s"] = clock() - mark
        if solution.success and gait is not None:
            ankle, impulse = variant_flags(task.variant)
            row = summary_row(gait, ankle=ankle, impulse=impulse, speed_mode=task.speed_mode,
                              file=task.relfile)
            result = solution.result
        else:
            row = failed_point_row(task, _failure_status(solution),
                                   iterations=sum(s.iterations for s in solution.stages),
                                   wall_time_s=solution.wall_time_s)
    except MotionOutOfReachError as exc:  # converged on the grid, not a gait between knots
        error = str(exc)
        row = failed_point_row(task, "failed: motion leaves a leg's reach between knots",
                               iterations=sum(s.iterations for s in solution.stages)
                               if solution is not None else 0,
                               wall_time_s=clock() - start)
    except Exception as exc:  # a bug or an OS error: record the point as failed, go on
        error = traceback.format_exc()
        row = failed_point_row(task, f"error: {type(exc).__name__}: {exc}",
                               wall_time_s=clock() - start)
    if not task.force_fail:
        _BUILT.add(task.structure)
    stages = solution.stages if solution is not None else ()
    return PointOutcome(
        key=task.key, row=row, gait=data if row.success else None, result=result, warm=how,
        fell_back=warm is not None and bool(stages) and not any(
            s.success for s in stages if s.name in (WARM_START_STAGE, MONOTONE_RESTART_STAGE)),
        stages=len(stages), iterations=sum(s.iterations for s in stages),
        wall_time_s=clock() - start, worker=worker_name(),
        structures=frozenset(_BUILT), error=error, timings=timings)


def gait_file_matches(gait: Gait, model: RobotModel, options: GaitOptions) -> str:
    """Why a saved gait is not the converged solution of ``options`` on ``model`` ("" if
    it is): used to decide which points of an earlier run to keep."""
    if not gait.success:
        return f"its solve failed ({gait.status})"
    wanted = options.to_dict()
    # An option the gait file lacks was added after it was written: it had the default then.
    saved = {**GaitOptions.saved_defaults(), **{k: _plain(v) for k, v in gait.options.items()}}
    diff = sorted(k for k in set(wanted) | set(saved) if wanted.get(k) != saved.get(k))
    if diff:
        return f"it was solved with other options ({', '.join(diff)})"
    if _plain(gait.model_data) != _plain(model.to_dict()):
        return "it was solved for another model"
    return ""


def _plain(value: object) -> object:
    """Plain JSON data (dicts and lists) from the gait's frozen mappings and tuples."""
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value
