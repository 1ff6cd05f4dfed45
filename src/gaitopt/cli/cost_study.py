"""``gaitopt study --costs``: the cost study's command body (the sweeps of every model and
case on one backend, the direct solves, ``costs.csv``, the report and the findings;
docs/costs.md)."""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from pathlib import Path

from rich.console import Console

from gaitopt.cli.base import SharedBackend, UserError, parse_knots
from gaitopt.cli.report import write_cost_reports
from gaitopt.cli.sweep_progress import run_with_progress
from gaitopt.robot.biped import BipedStructureError
from gaitopt.study.plan import START_SPEED, SweepSpec, SweepSpecError
from gaitopt.study.worker import PointOutcome
from gaitopt.units import parse_speed


def parse_start_speed(text: str) -> float | str:
    """``--start-speed``: ``auto`` or a speed in m/s (``75m/min``, ``1.25m/s``; a bare number
    is m/s)."""
    from gaitopt.study.cost_start import AUTO_START

    if text.strip().lower() == AUTO_START:
        return AUTO_START
    try:
        return parse_speed(text)
    except ValueError as exc:
        raise UserError(f"--start-speed: {exc} (or {AUTO_START!r}: each model's other cases "
                        "start at its paper optimum's speed)") from None


def run_cost_study(console: Console, directory: Path, model_names: Sequence[str], *,
                   costs: Sequence[str], resting_powers: str, regularization: float,
                   formulation: str, start_speed: str = "auto",
                   clearance: float | None = None, gait: str = "auto",
                   knot_spacing: str = "cosine",
                   knots: str | None = None, strategy: str = "auto",
                   accuracy_pass: bool | None = None,
                   workers: int | None, scheduler: str | None) -> None:
    """``gaitopt study --costs``: each (model, case) sweep in turn on one backend (its
    processes keep their built problems; with ``--start-speed auto`` each model's paper case
    first, whose optimum sets the start of the model's other cases), then the direct solves,
    ``costs.csv``, the report and the findings."""
    from gaitopt.gait.api import as_model
    from gaitopt.gait.solve.refinement import diverging_text
    from gaitopt.study.cost_accuracy import AccuracyOutcome
    from gaitopt.study.cost_continuation import (
        best_free,
        case_neighbour,
        fixed_converged,
        fixed_seeds,
        neighbour_folder,
        neighbour_spec,
        resolve_neighbour,
    )
    from gaitopt.study.cost_start import StartChoice
    from gaitopt.study.cost_study import (
        ACCURACY,
        SMOOTHING_SETS_SPEED,
        CostStudyError,
        CostStudySpec,
        CostSweep,
        accuracy_tasks,
        collect_rows,
        run_accuracy,
        run_direct_solves,
        start_choice,
        write_settings,
    )
    from gaitopt.study.cost_table import write_cost_table

    start = time.perf_counter()
    powers: list[float] = []
    for item in (i.strip() for i in resting_powers.split(",") if i.strip()):
        try:
            powers.append(float(item))
        except ValueError:
            raise UserError(f"--resting-powers: {item!r} is not a number (W/kg, >= 0)") from None
    try:
        spec = CostStudySpec(models=tuple(as_model(m) for m in model_names),
                             costs=tuple(dict.fromkeys(costs)),
                             resting_powers=tuple(powers), regularization=regularization,
                             swing_clearance=clearance, gait=gait,
                             formulation=formulation,  # type: ignore[arg-type]
                             knots=None if knots is None else parse_knots(knots),
                             start_speed=parse_start_speed(start_speed),
                             knot_spacing=knot_spacing,  # type: ignore[arg-type]
                             strategy=strategy, accuracy=ACCURACY,
                             accuracy_pass=("auto" if accuracy_pass is None
                                            else "on" if accuracy_pass else "off"))
        # Every sweep's settings checked before anything is solved (the automatic start's
        # speed is not known yet: 12 m/min stands in for it here).
        spec.sweeps({m.name: StartChoice(speed=START_SPEED, rule="auto", reason="")
                     for m in spec.models})
    except (CostStudyError, SweepSpecError, BipedStructureError) as exc:
        raise UserError(str(exc)) from None
    starts = {m.name: start_choice(spec, m, directory) for m in spec.models
              if not spec.auto_start}
    write_settings(spec, directory, starts)
    n_cases = len(spec.models) * len(spec.cases)
    console.print(f"cost study {directory}: {n_cases} cases "
                  f"({', '.join(m.name for m in spec.models)} x "
                  f"{', '.join(c.tag for c in spec.cases)})", soft_wrap=True)
    shared = SharedBackend(workers, scheduler)
    counted = 0

    def run_sweep(sweep: CostSweep, count: str, *, folder: Path | None = None,
                  spec_: SweepSpec | None = None, seeds: dict[str, Path] | None = None,
                  how: str = "") -> None:
        console.print(f"{count} {sweep.model} ({sweep.formulation}): {sweep.case.label}, "
                      f"{how or f'from {sweep.spec.speeds[0] * 60.0:g} m/min'}",
                      soft_wrap=True)
        run_with_progress(console, spec_ or sweep.spec, folder or directory / sweep.subdir,
                          workers=workers, scheduler=scheduler, backend=shared.get(),
                          seeds=seeds)

    def continued(sweep: CostSweep, done: list[CostSweep], count: str) -> None:
        """A case of the continuation strategy (gaitopt.study.cost_continuation): the first
        case its sweep, cold; every other its speed-free optimum from its neighbour's, and
        its sweep only if that failed (its fixed-speed walk from the nearest case's)."""
        by_case = {d.case: d for d in done}
        neighbour = case_neighbour(sweep.case, list(by_case))
        best = (None if neighbour is None
                else best_free(directory / by_case[neighbour].subdir, spec.variant))
        if neighbour is not None and best is not None:
            path, row = best
            again = neighbour_spec(sweep.spec, row.speed_m_s)
            run_sweep(sweep, count, folder=neighbour_folder(directory / sweep.subdir, neighbour),
                      spec_=again, seeds={p.key: path for p in again.points},
                      how=f"from {neighbour.tag}'s speed-free optimum "
                          f"({row.speed_m_min:.2f} m/min)")
            if best_free(directory / sweep.subdir, spec.variant) is not None:
                return
        converged = [d.case for d in done
                     if fixed_converged(directory / d.subdir, d.spec) is not None]
        near = resolve_neighbour(sweep.case, [d.case for d in done], converged)
        seeds = ({} if near is None else
                 fixed_seeds(sweep.spec, directory / by_case[near].subdir, by_case[near].spec))
        run_sweep(sweep, count, seeds=seeds,
                  how=(f"from {sweep.spec.speeds[0] * 60.0:g} m/min, "
                       + (f"started from {near.tag}'s walk there" if seeds and near
                          else "cold")))

    with shared:  # closed without waiting for running points on Ctrl-C or an error
        for model in spec.models:
            if spec.auto_start:  # the paper case first: its optimum sets the others' start
                counted += "paper" in spec.costs
                run_sweep(spec.reference_sweep(model),
                          f"[{counted}/{n_cases}]" if "paper" in spec.costs else "[start]")
                starts[model.name] = start_choice(spec, model, directory)
                write_settings(spec, directory, starts)
                console.print(f"{model.name}: its other cases start at "
                              f"{starts[model.name].reason}", soft_wrap=True)
            solved_cases: list[CostSweep] = []
            for case in spec.solve_order(model):
                counted += 1
                sweep = spec.sweep_of(model, case, spec.start_of(model, case, starts))
                if spec.strategy_of(model) == "continuation":
                    continued(sweep, solved_cases, f"[{counted}/{n_cases}]")
                else:
                    run_sweep(sweep, f"[{counted}/{n_cases}]")
                solved_cases.append(sweep)
        if (backend := shared.backend) is not None:
            def done(sweep: CostSweep, outcome: PointOutcome | None, path: Path | None) -> None:
                what = (f"{outcome.row.speed_m_min:6.2f} m/min  step {outcome.row.step_length:.4f}"
                        f" m  cost {outcome.row.cost:.4g}" if path is not None and outcome
                        else (outcome.row.status if outcome else "the worker died"))
                console.print(f"{'ok  ' if path else 'FAIL'} direct {sweep.model} "
                              f"{sweep.case.tag}: {what}", soft_wrap=True)

            console.print("direct (staged) solves of each case's speed-free optimum, the "
                          "lower of the two optima is kept:", soft_wrap=True)
            try:
                kept, solved, failed = run_direct_solves(spec, directory, backend, done)
            except KeyboardInterrupt:
                shared.close_now()
                console.print("interrupted: every finished solve is saved; rerun the same "
                              "command to resume", soft_wrap=True)
                sys.exit(130)
            console.print(f"direct solves: {solved} solved, {failed} failed, {kept} kept",
                          soft_wrap=True)

            def refined(sweep: CostSweep, outcome: AccuracyOutcome | None,
                        path: Path | None) -> None:
                if path is None or outcome is None or outcome.gait is None:
                    what = outcome.status if outcome else "the worker died"
                else:
                    acc = outcome.gait.get("solver", {}).get("accuracy", {})
                    worst = acc.get("worst_estimate")
                    knots = "+".join(str(k) for k in (acc.get("knots") or {}).values())
                    what = (f"{knots} knots, {acc.get('worst_estimate_of', 'cost')} estimate "
                            f"{'none' if worst is None else f'{100 * worst:.2g} %'} "
                            f"({'within' if acc.get('within_target') else 'NOT within'} "
                            f"{100 * ACCURACY:g} %{diverging_text(acc)}), "
                            f"{outcome.iterations} iterations, "
                            f"{outcome.wall_time_s:.0f} s")
                console.print(f"{'ok  ' if path else 'FAIL'} accuracy {sweep.model} "
                              f"{sweep.case.tag}: {what}", soft_wrap=True)

            if spec.refines:
                todo = [f"{sweep.model} {sweep.case.tag}"
                        for sweep, _ in accuracy_tasks(spec, directory)]
                console.print(f"accuracy: each case's optimum refined until its estimates are "
                              f"within {100 * ACCURACY:g} % (on its check grid, then "
                              f"finer; {len(todo)} to solve: {', '.join(todo) or 'none'}):",
                              soft_wrap=True)
                try:
                    solved, failed = run_accuracy(spec, directory, backend, refined)
                except KeyboardInterrupt:
                    shared.close_now()
                    console.print("interrupted: every finished solve is saved; rerun the "
                                  "same command to resume", soft_wrap=True)
                    sys.exit(130)
                console.print(f"accuracy: {solved} solved, {failed} failed", soft_wrap=True)
    rows = collect_rows(spec, directory)
    table = write_cost_table(directory, rows)
    console.print(f"table: {table}", soft_wrap=True)
    checked = [r for r in rows if r.within_accuracy is not None]
    if checked:
        missed = [r for r in checked if not r.within_accuracy]
        console.print(f"accuracy: {len(checked) - len(missed)} of {len(checked)} cases within "
                      f"{100 * ACCURACY:g} %" + ("" if not missed else "; not within: " + "; ".join(
                          f"{r.model} {r.case} ({r.status})" for r in missed)), soft_wrap=True)
    unset = [r for r in rows if r.success and r.smoothing_share > SMOOTHING_SETS_SPEED]
    if unset:
        console.print("no optimal speed of their own (the smoothing sets it; the cost falls "
                      "with the speed; not refined, not counted above): " + "; ".join(
                          f"{r.model} {r.case} (found at {r.speed_m_min:.1f} m/min)"
                          for r in unset), soft_wrap=True)
    smoothed = [r for r in rows if r.success and r.smoothing_share > ACCURACY]
    if smoothed:
        console.print(f"cost smoothing above {100 * ACCURACY:g} % of the cost (the smoothing, "
                      "not only the motion, sets these optima; docs/costs.md): " + "; ".join(
                          f"{r.model} {r.case} {100 * r.smoothing_share:.2g} %"
                          for r in smoothed), soft_wrap=True)

    page = write_cost_reports(console, directory, directory / "report")
    console.print(f"cost study done in {time.perf_counter() - start:.0f} s. Open {page}",
                  soft_wrap=True)
