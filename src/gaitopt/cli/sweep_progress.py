"""Running a sweep from the command line (:mod:`gaitopt.cli.study`): a progress bar (done,
failed, remaining, ETA) and a line per finished point; errors the user can fix become
:class:`~gaitopt.cli.base.UserError`, Ctrl-C exits with code 130 after saving every finished
point.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from gaitopt.cli.base import UserError
from gaitopt.gait.options.gait_options import GaitOptionsError
from gaitopt.robot.biped import BipedStructureError
from gaitopt.study.driver import Counts, SweepReport, SweepSettingsError, SweepStart, run_sweep
from gaitopt.study.executors import Backend, BackendError
from gaitopt.study.plan import SweepPoint, SweepSpec, SweepSpecError
from gaitopt.study.worker import PointOutcome


def point_line(point: SweepPoint, outcome: PointOutcome) -> str:
    """One line per finished point: variant, speed, cost, step length, status, iterations,
    time, how it started."""
    row = outcome.row
    if point.speed is None:
        speed = (f"free ({row.speed_m_min:5.2f})" if math.isfinite(row.speed_m_min)
                 else "free")
    else:
        speed = f"{point.speed * 60:6.2f}"
    extra = f" [{point.subdir}]" if point.subdir else ""
    start = {"result": "warm", "result, secant": "warm (secant)", "file": "warm (file)",
             "file, regridded": "warm (file, regridded)",
             "file, values": "warm (file values)", "none": "cold"}.get(outcome.warm,
                                                                           outcome.warm)
    if outcome.fell_back:
        start += " -> cold"
    head = f"{'ok  ' if row.success else 'FAIL'} {point.variant:<13}{extra} {speed:>13} m/min"
    if row.success:
        body = (f"cost {row.cost:9.3f}  step {row.step_length:.4f} m  {row.status}")
    else:
        body = row.status
    return (f"{head}  {body}  it {outcome.iterations:4d}  {outcome.wall_time_s:5.2f} s  "
            f"{start}")


def run_with_progress(console: Console, spec: SweepSpec, directory: Path, *,
                      workers: int | None, scheduler: str | None,
                      fail_points: Sequence[str] = (),
                      backend: Backend | None = None,
                      seeds: Mapping[str, Path] | None = None) -> SweepReport:
    """:func:`run_sweep` with a progress bar (done/failed/remaining, ETA) and a line per
    finished point; errors the user can fix become :class:`UserError`. ``backend``: run on
    it (and leave it open) instead of starting one; ``seeds``: warm starts of the chains'
    first points (:func:`run_sweep`)."""
    progress = Progress(
        TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
        TextColumn("failed {task.fields[failed]}  remaining {task.fields[remaining]}"),
        TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
        console=console, transient=False)
    task_id: Any = None

    def on_start(start: SweepStart) -> None:
        nonlocal task_id
        c = start.counts
        console.print(f"sweep {start.directory}: {c.total} points, {c.kept} kept from an "
                      f"earlier run, {c.to_solve} to solve on {start.backend}", soft_wrap=True)
        for note in start.notes:
            console.print(f"  note: {note}", soft_wrap=True)
        if c.to_solve:
            progress.start()
            task_id = progress.add_task("solving", total=c.to_solve, failed=0,
                                        remaining=c.to_solve)

    def on_point(point: SweepPoint, outcome: PointOutcome, counts: Counts) -> None:
        progress.console.print(point_line(point, outcome), soft_wrap=True)
        progress.update(task_id, completed=counts.finished, failed=counts.failed,
                        remaining=counts.remaining)

    try:
        report = run_sweep(spec, directory, workers=workers, scheduler=scheduler,
                           on_start=on_start, on_point=on_point, fail_points=fail_points,
                           backend=backend, seeds=seeds)
    except (SweepSpecError, SweepSettingsError, BackendError, GaitOptionsError,
            BipedStructureError) as exc:
        raise UserError(str(exc)) from None
    finally:
        progress.stop()
    c = report.counts
    if report.interrupted:
        console.print(f"interrupted after {c.finished} of {c.to_solve} points; every finished "
                      "point is saved: rerun the same command to resume", soft_wrap=True)
        sys.exit(130)
    console.print(f"done in {report.wall_time_s:.1f} s: {c.succeeded} solved, {c.failed} "
                  f"failed, {c.kept} kept ({c.total} points); summary: "
                  + ", ".join(str(p) for p in report.summaries), soft_wrap=True)
    if c.failed:
        console.print("failed points are listed in the summary as failed; rerun the same "
                      "command to try them again", soft_wrap=True)
    return report
