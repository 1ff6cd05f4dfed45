"""The cost study's accuracy pass: each case's optimum refined until its estimates are within 1 %.

The cases' optima are found on the study's grid (8 + 5 knots for the paper's walk, 24 + 16
for the heel-toe walk). After every start of every case has been solved, the lowest optimum of
each case (:func:`gaitopt.study.cost_study.collect_rows`) is solved again as ``gaitopt solve``
solves by default (:mod:`gaitopt.gait.solve.refinement`): warm-started from its gait file on
the same grid, then on the check grid (1.5 times the knots), whose change gives the relative
estimates of the cost, speed and step length (:func:`~gaitopt.gait.solve.refinement.
relative_estimates`); while the largest exceeds the accuracy (1 %), on the check grid's
check grid, at most :data:`ACCURACY_ROUNDS` times. Its gait (the
finest converged grid's) is written to ``<case>/accurate.gait.json`` with, in
``accurate.json``, the file and cost it started from, so a rerun keeps it while the case's
optimum is the same. The table reports the accurate gait's values and estimate
(``estimate``, ``estimate_of``, ``knots``, ``within_accuracy``).
"""

from __future__ import annotations

import json
import math
import time
import traceback
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gaitopt.fileio import write_text_atomic
from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.gait.solve.record import gait_from_run
from gaitopt.gait.solve.staged_run import StageRecord
from gaitopt.robot.model import RobotModel

#: The most refinements of a case's optimum (one more than ``gaitopt solve``'s
#: :data:`~gaitopt.gait.solve.refinement.MAX_ROUNDS`): the heel-toe walk's study grid
#: 24+18 knots (as its stages print them) -> 36+26 -> 54+39 -> 81+57 -> 122+86.
#: Measured 2026-12-03 (docs/costs.md, "The accuracy pass"): the seven-link's slow optima
#: (work, metabolic 0 W/kg, 18-19 m/min) change their cost by 2.8, 1.9, 0.8 and 0.4 % from
#: grid to grid, so their first-order estimate (three times the change) was 1.3 and 1.5 %
#: after three rounds.
ACCURACY_ROUNDS = 4

#: The accurate gait of a case and the note of what it started from, in the case's folder.
ACCURATE_FILE = "accurate.gait.json"
ACCURATE_NOTE = "accurate.json"


@dataclass(frozen=True, kw_only=True)
class AccuracyTask:
    """One case's accuracy pass: ``key`` the case folder (relative to the study's), the
    model, the options (the case's, with the accuracy to reach), and the text of the gait
    file it starts from (``source`` its path relative to the study's folder, ``cost`` its
    cost)."""

    key: str
    model: RobotModel
    options: GaitOptions
    text: str
    source: str
    cost: float
    #: Print a line per finished stage (the worker's standard output: the terminal for local
    #: processes, a Dask worker's log).
    echo: bool = True


@dataclass(frozen=True, kw_only=True)
class AccuracyOutcome:
    """What came of one accuracy pass: ``gait`` the refined gait as plain data (None when the
    solve failed), ``status`` IPOPT's status or the error, ``wall_time_s``, ``iterations``
    (all stages)."""

    key: str
    gait: Mapping[str, Any] | None
    status: str
    wall_time_s: float
    iterations: int
    error: str = ""


def solve_accurate(task: AccuracyTask) -> AccuracyOutcome:
    """The accuracy pass of one case (module docstring); never raises for a failed solve."""
    start = time.perf_counter()
    try:
        gait = Gait.from_dict(json.loads(task.text), source=task.source)
        def echo(stage: StageRecord) -> None:
            print(f"  accuracy {task.key}: {stage.line()}", flush=True)

        run = solve_staged_run(task.model, task.options, warm_start=gait, refine=True,
                               check_warm_start=True, progress=echo if task.echo else None,
                               max_rounds=ACCURACY_ROUNDS)
        data = gait_from_run(run).to_dict() if run.success else None
        return AccuracyOutcome(key=task.key, gait=data, status=run.result.status,
                               wall_time_s=time.perf_counter() - start,
                               iterations=sum(s.iterations for s in run.stages))
    except Exception as exc:  # a bug or an OS error: the case keeps its study-grid optimum
        return AccuracyOutcome(key=task.key, gait=None,
                               status=f"error: {type(exc).__name__}: {exc}",
                               wall_time_s=time.perf_counter() - start, iterations=0,
                               error=traceback.format_exc())


def accurate_gait(case_folder: Path, source: str, cost: float) -> Gait | None:
    """The case's accurate gait when it was refined from ``source`` (the winning gait file,
    relative to the study's folder) of cost ``cost`` and converged, and is within its
    accuracy, was refined :data:`ACCURACY_ROUNDS` times or stopped because its estimate grew
    (``diverging``); else None (to solve: a gait refined fewer times, by an older pass, is
    refined again)."""
    try:
        note = json.loads((case_folder / ACCURATE_NOTE).read_text(encoding="utf-8"))
        if note.get("from") != source or not math.isclose(float(note.get("from_cost")), cost,
                                                          rel_tol=1e-12):
            return None
        gait = Gait.load(case_folder / ACCURATE_FILE)
        record = gait.solver.get("accuracy") or {}
        short = (record.get("within_target") is False and not record.get("diverging")
                 and int(record.get("refinements") or 0) < ACCURACY_ROUNDS)
    except (OSError, ValueError, TypeError, GaitFileError):
        return None
    return gait if gait.success and not short else None


def save_accurate(case_folder: Path, task: AccuracyTask, outcome: AccuracyOutcome) -> Path | None:
    """Write the accurate gait (if the solve converged) and its note atomically; the path of
    the gait file, or None. A failed pass writes its note only (``"failed": true``, its
    status), which the table reports (:func:`accuracy_failure`); a rerun solves it again."""
    note = {"from": task.source, "from_cost": task.cost, "status": outcome.status,
            "iterations": outcome.iterations, "wall_time_s": outcome.wall_time_s,
            "failed": outcome.gait is None}
    if outcome.gait is None:
        write_text_atomic(case_folder / ACCURATE_NOTE, json.dumps(note, indent=2) + "\n")
        return None
    path = case_folder / ACCURATE_FILE
    Gait.from_dict(outcome.gait, source=str(path)).save(path)
    write_text_atomic(case_folder / ACCURATE_NOTE, json.dumps(note, indent=2) + "\n")
    return path


def accuracy_failure(case_folder: Path, source: str, cost: float) -> str | None:
    """The status of the case's failed accuracy pass from ``source`` of cost ``cost`` (its
    note, :func:`save_accurate`), or None when there is no such failure."""
    try:
        note = json.loads((case_folder / ACCURATE_NOTE).read_text(encoding="utf-8"))
        same = note.get("from") == source and math.isclose(float(note.get("from_cost")), cost,
                                                           rel_tol=1e-12)
    except (OSError, ValueError, TypeError):
        return None
    return str(note.get("status") or "failed") if same and note.get("failed") else None


def estimate_of(gait: Gait) -> tuple[float, str, bool | None, str]:
    """``(worst relative estimate, its name, within the target, knots)`` of a gait's
    ``solver.accuracy`` (NaN, ``""``, None where missing; knots as ``24+16`` by phase, in
    phase order)."""
    acc = gait.solver.get("accuracy") or {}
    worst = acc.get("worst_estimate")
    knots = acc.get("knots") or {}
    return (float(worst) if worst is not None else math.nan,
            str(acc.get("worst_estimate_of") or ""),
            acc.get("within_target"),
            "+".join(str(int(k)) for k in knots.values()))


__all__ = ["ACCURACY_ROUNDS", "ACCURATE_FILE", "ACCURATE_NOTE", "AccuracyOutcome",
           "AccuracyTask", "accuracy_failure", "accurate_gait", "estimate_of", "save_accurate",
           "solve_accurate"]
