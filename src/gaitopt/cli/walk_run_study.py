"""``gaitopt study --walk-run``: the walk-run study's command body (each model's, cost's and
branch's sweep on one backend, a second pass over the failed points, ``walk_run.csv``,
``transitions.csv``, the report and the findings; docs/running.md)."""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

from rich.console import Console

from gaitopt.cli.base import SharedBackend, UserError, parse_knots
from gaitopt.cli.sweep_grid import parse_speeds
from gaitopt.cli.sweep_progress import run_with_progress
from gaitopt.robot.biped import BipedStructureError
from gaitopt.study.plan import SweepSpecError


def run_walk_run_study(console: Console, directory: Path, model_names: Sequence[str], *,
                       costs: Sequence[str], speeds: str | None, knots: str | None,
                       knot_spacing: str, workers: int | None,
                       scheduler: str | None) -> None:
    """``gaitopt study --walk-run`` (module docstring). Every sweep's settings are checked
    before anything is solved; a rerun resumes (each sweep keeps its finished points)."""
    from gaitopt.gait.api import as_model
    from gaitopt.gait.options.gait_options import GaitOptionsError
    from gaitopt.study.driver import check_points
    from gaitopt.study.findings import findings_text
    from gaitopt.study.walk_run import (
        WalkRunSpec,
        WalkRunStudyError,
        collect_rows,
        transitions,
        write_settings,
        write_table,
        write_transitions,
    )
    from gaitopt.viz.walk_run_report import write_walk_run_report

    start = time.perf_counter()
    try:
        spec = WalkRunSpec(models=tuple(as_model(m) for m in model_names),
                           costs=tuple(dict.fromkeys(costs)),
                           speeds=None if speeds is None else parse_speeds(speeds),
                           knots=None if knots is None else parse_knots(knots),
                           knot_spacing=knot_spacing)  # type: ignore[arg-type]
        sweeps = spec.sweeps()
        for _, _, _, _, sweep in sweeps:
            check_points(sweep)
    except (WalkRunStudyError, SweepSpecError, BipedStructureError, GaitOptionsError,
            ValueError) as exc:
        raise UserError(str(exc)) from None
    write_settings(spec, directory)
    console.print(f"walk-run study {directory}: {len(sweeps)} sweeps "
                  f"({', '.join(m.name for m in spec.models)} x {', '.join(spec.costs)} x "
                  "their branches)", soft_wrap=True)
    with SharedBackend(workers, scheduler) as shared:  # not waited for on Ctrl-C, an error
        for k, (subdir, model, cost, branch, sweep) in enumerate(sweeps, start=1):
            console.print(f"[{k}/{len(sweeps)}] {model.name}: {branch.label}, {cost} cost, "
                          f"{len(sweep.speeds)} speeds {sweep.speeds[0] * 60:g}-"
                          f"{sweep.speeds[-1] * 60:g} m/min, {sweep.knots[0]}+{sweep.knots[1]} "
                          "knots", soft_wrap=True)
            backend = shared.get()
            report = run_with_progress(console, sweep, directory / subdir, workers=workers,
                                       scheduler=scheduler, backend=backend)
            if report.counts.failed:  # once more, from the converged neighbours' gait files
                console.print(f"{report.counts.failed} failed: solving them again, each from "
                              "its converged neighbour's gait file", soft_wrap=True)
                run_with_progress(console, sweep, directory / subdir, workers=workers,
                                  scheduler=scheduler, backend=backend)
    rows = collect_rows(spec, directory)
    table = write_table(directory, rows)
    found = transitions(spec, rows)
    console.print(f"table: {table}; transitions: {write_transitions(directory, found)}",
                  soft_wrap=True)
    info = write_walk_run_report(rows, found, directory / "report")
    for t in found:
        tr = t.transition
        if tr.kind == "crossing":
            what = (f"walk -> run at {tr.speed * 60:.1f} m/min (bracket {tr.bracket[0] * 60:g}-"
                    f"{tr.bracket[1] * 60:g}, grid error {tr.interval[0] * 60:.1f}-"
                    f"{tr.interval[1] * 60:.1f} m/min), Froude {t.froude:.2f} on "
                    f"{t.leg_length_m:.3f} m legs")
        else:
            what = f"no walk-to-run crossing ({tr.kind})"
        console.print(f"{t.model} / {t.cost}: {what}", soft_wrap=True)
    for key, items in info.findings.items():
        console.print(f"findings {key}:", soft_wrap=True)
        console.print("\n".join(findings_text(items).splitlines()[1:]), soft_wrap=True)
    console.print(f"walk-run study done in {time.perf_counter() - start:.0f} s. Open "
                  f"{info.html}", soft_wrap=True)
    failed = sum(not r.success for r in rows)
    if failed:
        console.print(f"{failed} of {len(rows)} points failed (in the table as failed)",
                      soft_wrap=True)
