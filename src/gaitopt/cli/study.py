"""``gaitopt sweep`` and ``study`` (the main job): many gaits.

``sweep`` solves a grid (variants x speeds, optionally x step lengths x single-support
fractions) in parallel with continuation and writes a resumable sweep directory; ``study``
does that for the paper's study, then ``report`` and ``animate`` (:mod:`gaitopt.cli.report`).
See docs/studies.md.
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import click
from rich.console import Console

from gaitopt.cli.base import (
    UserError,
    cli,
    control_model_option,
    cost_option,
    formulation_option,
    grid_choice,
    knot_spacing_option,
    knots_option,
    make_console,
    min_knee_flexion_option,
    model_option,
    paper_grid_option,
    resting_power_option,
)
from gaitopt.cli.cost_study import run_cost_study
from gaitopt.cli.report import animate_file, write_reports
from gaitopt.cli.sweep_grid import make_spec, parse_speeds, parse_variants
from gaitopt.cli.sweep_progress import run_with_progress
from gaitopt.cli.walk_run_study import run_walk_run_study
from gaitopt.gait.formulations.select import default_formulation
from gaitopt.gait.options.gait_options import GAITS, GaitOptions, GaitOptionsError
from gaitopt.study.driver import default_workers
from gaitopt.study.grid_error import (
    CHECK_DIR,
    MAX_REFINE_LEVELS,
    WITHIN,
    GridError,
    check_knots,
    grid_error,
    refine_dir_name,
)
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, VARIANTS

#: Default speed grid of ``gaitopt sweep`` (m/min): the paper's 3 to 60 m/min.
DEFAULT_SPEEDS = "3:60:3"
#: Default speed grid of ``gaitopt study`` (m/min): the paper's 3 to 60 m/min for the walk.
STUDY_SPEEDS = "3:60:3"
#: ... and for the heel-toe walk of a model with feet (``seven-link``; issue 25): 12 to 120
#: m/min in steps of 12, ten speeds around people's 80 m/min (44 points with the four
#: variants' speed-free optima: about as many as the five-link study's 84 take to solve).
FEET_STUDY_SPEEDS = "12:120:12"
#: The default speed grid by the gait of the study's model.
STUDY_SPEEDS_BY_GAIT = {"walk": STUDY_SPEEDS, "heel-toe": FEET_STUDY_SPEEDS}
STUDY_DIR = Path("out/study")
#: Default directory and resting powers (W/kg) of ``gaitopt study --costs``.
COSTS_DIR = Path("out/costs")
#: Default directory and models of ``gaitopt study --walk-run`` (docs/running.md).
WALK_RUN_DIR = Path("out/walk-run")
WALK_RUN_MODELS = ("five-link", "seven-link", "adult-point-feet")
DEFAULT_RESTING_POWERS_TEXT = "0,0.6,1.2,2.4,4.8"


def _workers_option(f: Any) -> Any:
    f = click.option("--scheduler", default=None, metavar="ADDRESS",
                     help="Run on a Dask cluster (e.g. tcp://host:8786) instead of local "
                          "processes; its workers need gaitopt, not this directory (this "
                          "process writes every result).")(f)
    return click.option("--workers", type=click.IntRange(min=0), default=None,
                        help="Local worker processes (default: the CPUs available, "
                             f"{default_workers()} here; 0 = in this process).")(f)


@cli.command("sweep")
@click.option("-o", "--output", "directory", type=click.Path(file_okay=False, path_type=Path),
              required=True, help="Sweep directory (created; rerun to resume).")
@model_option
@click.option("--speeds", default=DEFAULT_SPEEDS, show_default=True,
              help="Speeds in m/min: start:stop:step (stop included) and/or a comma list.")
@click.option("--variants", default="all", show_default=True,
              help=f"'all' or a comma list of {', '.join(VARIANTS)}.")
@click.option("--free/--no-free", default=True, show_default=True,
              help="Also solve the speed-free optimal walk of each variant.")
@click.option("--step-length", default="free", show_default=True,
              help="Step lengths in m (comma list), or 'free'.")
@click.option("--step-time", default="free", show_default=True,
              help="Step times in s (comma list), or 'free'; not with --step-length.")
@click.option("--single-support", default="0.85", show_default=True,
              help="Single-support fractions of the step time (comma list).")
@knots_option
@paper_grid_option
@formulation_option(help="The coordinates of every point (docs/formulations.md) [default: "
                         "reduced for the five-link shape and the walk, else full].",
                    default=None)
@click.option("--gait", "gait_kind", type=click.Choice(list(GAITS)), default=None,
              help="The contact sequence of every point (heel-toe: feet, e.g. --model "
                   "seven-link) [default: what the model's contact points allow: walk with "
                   "one per leg, heel-toe with two].")
@cost_option(help="The cost of every point (docs/costs.md).")
@resting_power_option
@control_model_option(help="Controls continuous and periodic (paper) or free to "
                                      "jump at the events.")
@min_knee_flexion_option
@knot_spacing_option("The knots of each phase: cosine-spaced (clustered at the events, the "
                     "default of every solve since 2026-12-02; docs/walking.md section 6) or "
                     "uniform.")
@_workers_option
def sweep_command(directory: Path, model_name: str, speeds: str, variants: str, free: bool,
                  step_length: str, step_time: str, single_support: str, knots: str | None,
                  paper_grid: bool, formulation: str | None, gait_kind: str | None, cost: str,
                  resting_power: float | None, control_model: str | None,
                  knot_spacing: str | None,
                  min_knee_flexion: float | None, workers: int | None,
                  scheduler: str | None) -> None:
    """Solve a grid of walking problems in parallel, by continuation in speed.

    Writes DIR/sweep.json (the settings), a gait file per solved point and DIR/summary.csv.
    Rerunning the same command resumes: finished points are kept. Exit status 1 if a point
    failed.
    """
    console = make_console()
    if gait_kind is None or formulation is None:
        from gaitopt.gait.api import as_model
        from gaitopt.gait.options.model_defaults import default_gait

        try:
            model = as_model(model_name)
            if gait_kind is None:
                try:
                    gait_kind = default_gait(model)
                except GaitOptionsError:  # no built-in gait fits: the walk's checks explain
                    gait_kind = "walk"
            if formulation is None:
                formulation = default_formulation(model, gait_kind, False)
        except ValueError as exc:
            raise UserError(str(exc)) from None
    problem: dict[str, Any] = {"formulation": formulation, "cost": cost, "gait": gait_kind,
                               "knot_spacing": GaitOptions().knot_spacing,
                               **grid_choice(knots, control_model, paper_grid, knot_spacing)}
    if resting_power is not None:
        problem["resting_power"] = resting_power
    if min_knee_flexion is not None:
        problem["min_stance_knee_flexion"] = min_knee_flexion
    spec = make_spec(model_name=model_name, speeds=speeds, variants=variants, free=free,
                     step_length=step_length, single_support=single_support,
                     step_time=step_time, problem=problem)
    report = run_with_progress(console, spec, directory, workers=workers, scheduler=scheduler)
    if report.counts.failed:
        sys.exit(1)


# -- the main job -------------------------------------------------------------------------------

@cli.command("study")
@click.option("-o", "--output", "directory", type=click.Path(file_okay=False, path_type=Path),
              default=None, help=f"Study directory (the sweep; the report goes to its report/ "
                                 f"folder) [default: {STUDY_DIR}; with --costs {COSTS_DIR}; "
                                 f"with --walk-run {WALK_RUN_DIR}].")
@click.option("--model", "model_names", multiple=True,
              help="Built-in model name or model file [default: five-link]; with --costs "
                   "repeat it to compare models; with --walk-run [default: "
                   f"{', '.join(WALK_RUN_MODELS)}].")
@click.option("--speeds", default=None,
              help=f"Speeds in m/min: start:stop:step and/or a comma list [default: "
                   f"{STUDY_SPEEDS}; {FEET_STUDY_SPEEDS} for a model with feet].")
@click.option("--costs", "cost_study", is_flag=True,
              help="The cost study instead (docs/costs.md): each model's speed-free optimum "
                   "of the paper's, the work and the metabolic cost at each resting power.")
@click.option("--walk-run", "walk_run", is_flag=True,
              help="The walk-run study instead (docs/running.md): at each speed each model's "
                   "optimal walk, walk without double support (if it allows it) and run, the "
                   "cheapest and the walk-run transition, under the paper's and the metabolic "
                   "cost.")
@click.option("--cost", "costs", multiple=True,
              type=click.Choice(["paper", "work", "metabolic"]),
              help="The cost study of these costs only (repeat it; implies --costs); with "
                   "--walk-run its costs (paper, metabolic) [default: both].")
@click.option("--accuracy-pass/--no-accuracy-pass", default=None,
              help="With --costs: refine each case's optimum until its estimates of cost, "
                   "speed and step length are within 1 % (its check grid, then finer); a "
                   "case that does not get there is marked so [default: on for models with "
                   "feet (the heel-toe walk), off for the paper's walk; docs/costs.md].")
@click.option("--resting-powers", default=DEFAULT_RESTING_POWERS_TEXT, show_default=True,
              help="With --costs: resting powers of the metabolic cost, W/kg (comma list).")
@click.option("--regularization", type=float, default=0.0, show_default=True,
              help="With --costs: weight of the torque regularisation added to the work and "
                   "metabolic costs.")
@click.option("--start-speed", default="auto", show_default=True,
              help="With --costs: the speed of each case's cold start, from which its "
                   "speed-free optimum is warm-started (e.g. 75m/min); auto: each model's "
                   "paper case starts at 12 m/min, its other cases at the speed of the paper "
                   "case's optimum rounded to 3 m/min.")
@click.option("--clearance", type=float, default=None,
              help="With --costs: least mid-swing height of the swing tip in m, every case "
                   "(the work cost's optimum drags the swing tip otherwise).")
@click.option("--gait", "gait_kind", type=click.Choice(["auto", "walk", "heel-toe"]),
              default="auto", show_default=True,
              help="With --costs: the contact sequence (auto: heel-toe for a model with feet, "
                   "else the paper's walk).")
@click.option("--formulation", type=click.Choice(["auto", "reduced", "full"]), default="auto",
              show_default=True, help="With --costs: the coordinates (auto: reduced for the "
                                      "five-link biped, full for any other model).")
@click.option("--paper-grid", is_flag=True,
              help="The paper's setting: 8+5 knots and its control model (continuous, "
                   "periodic controls); checked against 16+6 knots.")
@knots_option
@knot_spacing_option("The knots of each phase of the paper's study (and of the cost study): "
                     "cosine-spaced (clustered at the events) or uniform.")
@_workers_option
def study_command(directory: Path | None, model_names: tuple[str, ...], speeds: str | None,
                  paper_grid: bool, knots: str | None, knot_spacing: str | None,
                  cost_study: bool, walk_run: bool, accuracy_pass: bool | None,
                  costs: tuple[str, ...],
                  resting_powers: str,
                  regularization: float, start_speed: str, clearance: float | None,
                  gait_kind: str,
                  formulation: str, workers: int | None, scheduler: str | None) -> None:
    """The paper's study: the four variants over the speed grid plus each speed-free
    optimum (cosine-spaced 16+6 knots), the same on a finer grid (DIR/check-grid) for the
    error estimates, the points whose estimate exceeds 1 % finer still (DIR/refine-grid),
    then the report (Figs. 3-8 with their grid and error estimate, findings) and an animation
    of the optimal walk. A model with feet (seven-link) walks heel to toe in full coordinates
    on 24+16 knots, 12-120 m/min; without ankle torques its ankles are passive (damped).
    With --costs, the cost study (docs/costs.md); with --walk-run, the walk-run study
    (docs/running.md). Rerunning resumes."""
    from gaitopt.study.findings import optimal_row
    from gaitopt.study.summary import read_summary

    console = make_console()
    if walk_run:
        if cost_study:
            raise UserError("--walk-run and --costs are two studies: give one of them")
        if paper_grid:
            raise UserError("--paper-grid: not with --walk-run (its grid is each gait's "
                            "default, or --knots)")
        if "work" in costs:
            raise UserError("--cost work: not with --walk-run (its costs: paper, metabolic)")
        run_walk_run_study(console, directory or WALK_RUN_DIR, model_names or WALK_RUN_MODELS,
                           costs=costs or ("paper", "metabolic"), speeds=speeds, knots=knots,
                           knot_spacing=knot_spacing or GaitOptions().knot_spacing,
                           workers=workers, scheduler=scheduler)
        return
    if cost_study or costs:
        run_cost_study(console, directory or COSTS_DIR, model_names or ("five-link",),
                       costs=costs or ("paper", "work", "metabolic"),
                       resting_powers=resting_powers, regularization=regularization,
                       start_speed=start_speed, clearance=clearance, gait=gait_kind,
                       formulation=formulation,
                       knot_spacing=knot_spacing or GaitOptions().knot_spacing,
                       knots=knots, accuracy_pass=accuracy_pass, workers=workers,
                       scheduler=scheduler)
        return
    if len(model_names) > 1:
        raise UserError("--model: the paper's study takes one model (several only with "
                        "--costs)")
    directory = directory or STUDY_DIR
    start = time.perf_counter()
    grid = {"knot_spacing": GaitOptions().knot_spacing,
            **grid_choice(knots, None, paper_grid, knot_spacing)}
    model_name = model_names[0] if model_names else "five-link"
    spec = study_spec(model_name, speeds, grid)
    console.print(f"study of {spec.model.name}: {spec.base.gait} walk, "
                  f"{spec.base.formulation} coordinates, {spec.knots[0]}+{spec.knots[1]} knots, "
                  f"{len(spec.speeds)} speeds {spec.speeds[0] * 60:g}-{spec.speeds[-1] * 60:g} "
                  f"m/min, variants {', '.join(spec.variants)}"
                  + (f" (without ankle torques: {spec.passive_model.name})"
                     if spec.passive_model is not spec.model else ""), soft_wrap=True)
    solve_study_sweep(console, spec, directory, workers=workers, scheduler=scheduler)
    finer = check_knots(spec.knots)
    console.print(f"check grid {finer[0]}+{finer[1]} knots (the error estimates):",
                  soft_wrap=True)
    check, seeds = check_sweep(study_spec(model_name, speeds, {**grid, "knots": finer}),
                               directory)
    solve_study_sweep(console, check, directory / CHECK_DIR, workers=workers,
                      scheduler=scheduler, seeds=seeds)
    rows = read_summary(directory / SUMMARY_FILE)
    if not paper_grid:  # the paper's setting is reported as it is, with its estimate
        refine_points(console, directory, spec, grid_error(directory, rows),
                      workers=workers, scheduler=scheduler)
    out = directory / "report"
    pages = write_reports(console, directory, out, workers=workers)
    errors = grid_error(directory, rows)
    if errors is not None:
        rows = errors.reported(rows)
        console.print(errors.statement(), soft_wrap=True)
        for v in VARIANTS:
            p = errors.free(v)
            if p is not None:
                console.print(f"  {v} optimum {p.row.speed_m_min:.2f} m/min, step "
                              f"{p.row.step_length:.4f} m, cost {p.row.cost:.4g}; on the check "
                              f"grid speed {p.speed_m_min:+.2f} m/min, step "
                              f"{p.step_length:+.4f} m, cost {100 * p.cost:.2f} %",
                              soft_wrap=True)
    best = next((r for v in VARIANTS if (r := optimal_row(rows, v)) is not None), None)
    if best is not None:
        animate_file(console, directory / best.file, out / "optimal-walk.gif", steps=4,
                     fps=30)
        console.print(f"(the animated gait is the {best.variant} optimum, "
                      f"{best.speed_m_min:.1f} m/min, step {best.step_length:.3f} m)",
                      soft_wrap=True)
    else:
        console.print("no point converged: no animation", soft_wrap=True)
    console.print(f"study done in {time.perf_counter() - start:.0f} s. Open {pages[0]}",
                  soft_wrap=True)


def study_spec(model_name: str, speeds: str | None, grid: dict[str, Any]) -> SweepSpec:
    """The sweep of the paper's study on a model: every variant over ``speeds`` (m/min text;
    None: the default of the model's gait, :data:`STUDY_SPEEDS_BY_GAIT`) plus each speed-free
    optimum, single support 0.85 of the step, step free; ``grid`` the shared problem options
    (knots, knot spacing, control model). The gait, formulation, knots and bounds follow the
    model (:class:`~gaitopt.study.plan.SweepSpec` resolves them as ``gaitopt solve`` does:
    the five-link walk in reduced coordinates on 16+6 knots, a model with feet heel to toe in
    full coordinates on 24+16); a variant without ankle torques on feet has passive ankles
    (:func:`~gaitopt.study.plan.passive_ankles`). A walk with feet (any contact sequence but
    the two-phase walk) starts each impulse variant's chain from its variant without the
    impulse (``SweepSpec.impulse_from_no_impulse``): the cold starts at 72 m/min took 400-600
    iterations and 22-45 s each; the five-link walk's cold starts take about a second and
    stay cold, as in the paper. With feet, too, every point with ankle torques and the
    impulse starts from the same point with ankle torques only
    (``SweepSpec.ankle_impulse_from_ankle``), on every grid of the study, and a chain's
    third and later points start from the secant prediction through the two before
    (``SweepSpec.secant``), and the cold starts leave their check grid to the study's check
    sweep (``SweepSpec.check_cold``)."""
    def spec_of(text: str) -> SweepSpec:
        return make_spec(model_name=model_name, speeds=text, variants="all", free=True,
                         step_length="free", single_support="0.85", problem=grid)

    spec = spec_of(speeds or STUDY_SPEEDS)
    default = STUDY_SPEEDS_BY_GAIT.get(str(spec.base.gait), STUDY_SPEEDS)
    spec = spec_of(default) if speeds is None and default != STUDY_SPEEDS else spec
    return spec if spec.base.gait == "walk" else replace(spec, impulse_from_no_impulse=True,
                                                         ankle_impulse_from_ankle=True,
                                                         secant=True, check_cold=False)


def check_sweep(check: SweepSpec, directory: Path) -> tuple[SweepSpec, dict[str, Path]]:
    """The study's check sweep (``check``: the study's spec on the check grid) and its seeds,
    for a study in ``directory``. The five-link walk as ``check`` says: chains along the
    speed axis, each from a cold start. A walk with feet (any contact sequence but the
    two-phase walk): each fixed-speed point warm-started from the study's gait of the same
    point where it converged (its point and multipliers mapped onto the finer grid,
    :func:`gaitopt.gait.api.regridded_point`; no continuation in speed), so the check grid
    solves the optimum the estimate compares with; each speed-free optimum
    from its group's check point at the start speed (values and multipliers, as before:
    from its own gait's values the check grid's optimum moved by 3 m/min, to a dearer one).

    Measured on the seven-link study (docs/studies.md, "The check sweep with feet"):
    chained from the neighbour at the next speed, the check grid reached other local optima
    than the study's grid at 12 and 24 m/min (8.5 % and 1.4 % apart), which the estimate read
    as grid errors above 1 % and the refinement re-solved on up to 81 + 54 knots (900 s), and
    one chained point ran 476 iterations in 980 s (16 from its own gait)."""
    if check.base.gait == "walk":
        return check, {}
    alone = replace(check, continuation=False, free_from_start=True)
    return alone, {p.key: directory / p.key for p in alone.points
                   if alone.parents[p.key] is None and (directory / p.key).exists()}


def neighbour_seeds(spec: SweepSpec, directory: Path) -> dict[str, Path]:
    """For a sweep without continuation (:func:`check_sweep`), the warm starts of its points
    that have no gait file in ``directory`` (failed, or not solved yet): the gait file of
    the nearest fixed-speed point of the same group that converged (the same grid: its
    values and multipliers), as the rerun of a chained sweep starts a failed point from its
    converged neighbour's file. A speed-free point's nearest is the one at the start
    speed's side of the grid (its group's first converged point from the start speed)."""
    out: dict[str, Path] = {}
    for p in spec.points:
        if (directory / p.key).exists():
            continue
        speed = spec.start if p.speed is None else p.speed
        done = [q for q in spec.points if q.group == p.group and q.speed is not None
                and q.key != p.key and (directory / q.key).exists()]
        if done:
            out[p.key] = directory / min(done, key=lambda q: abs((q.speed or 0.0) - speed)).key
    return out


def solve_study_sweep(console: Console, spec: SweepSpec, directory: Path, *,
                      workers: int | None, scheduler: str | None,
                      seeds: dict[str, Path] | None = None) -> None:
    """One sweep of the study, then its convergence passes: the points that failed (an
    iteration limit, a restoration failure) solved once more, each warm-started from its
    converged neighbour's saved gait (the driver's rerun: another start than the first
    pass's, which continued from the neighbour's result in memory); then each speed-free
    optimum that costs more than a fixed-speed point of its variant (or failed) solved again
    from that point's gait, the lower of the two kept (:mod:`gaitopt.study.optima`).
    ``seeds``: warm starts of the chains' first points (:func:`run_with_progress`)."""
    from gaitopt.fileio import write_text_atomic
    from gaitopt.study.optima import (
        free_restarts,
        lower_gait,
        restart_folder,
        restart_seeds,
        restart_spec,
    )
    from gaitopt.study.summary import read_summary

    report = run_with_progress(console, spec, directory, workers=workers, scheduler=scheduler,
                               seeds=seeds)
    if report.counts.failed:
        console.print(f"{report.counts.failed} failed: solving them again, each from its "
                      "converged neighbour's gait file", soft_wrap=True)
        rerun = seeds if spec.continuation else {**(seeds or {}),
                                                 **neighbour_seeds(spec, directory)}
        run_with_progress(console, spec, directory, workers=workers, scheduler=scheduler,
                          seeds=rerun)
    restarts = free_restarts(read_summary(directory / SUMMARY_FILE), spec.variants)
    if not restarts:
        return
    replaced = False
    for variant, best in restarts.items():
        console.print(f"{variant}: the speed-free optimum is not below the fixed-speed point "
                      f"at {best.speed_m_min:g} m/min (cost {best.cost:.6g}): solving it "
                      "again from that point's gait", soft_wrap=True)
        again = restart_spec(spec, variant, best)
        folder = restart_folder(directory, variant)
        run_with_progress(console, again, folder, workers=workers, scheduler=scheduler,
                          seeds=restart_seeds(again, directory / best.file))
        free = next(p for p in again.points if p.speed is None)
        lower = lower_gait(directory / free.key, folder / free.key)
        if lower is not None and lower != directory / free.key:
            write_text_atomic(directory / free.key, lower.read_text(encoding="utf-8"))
            replaced = True
            console.print(f"{variant}: the restart's speed-free optimum is lower; kept",
                          soft_wrap=True)
    if replaced:  # the summary rebuilt from the gait files (every point kept)
        run_with_progress(console, spec, directory, workers=workers, scheduler=scheduler)


def refine_points(console: Console, directory: Path, study: SweepSpec,
                  errors: GridError | None, *, workers: int | None,
                  scheduler: str | None) -> None:
    """The refinement sweeps of a study (:mod:`gaitopt.study.grid_error`): the points whose
    estimate exceeds 1 % (cost, step length or the speed of a speed-free optimum; every
    variant at their speeds, and the speed-free optima if one of them is among them), solved
    on the next finer grid (1.5 times the knots) in ``DIR/refine-grid``, each warm-started
    from the check sweep's gait of the same point (no continuation: the points are
    independent and may be far apart in speed); then those whose estimate from their last
    two grids still exceeds 1 % on the next grid in ``DIR/refine-grid-2``, and so on, at
    most :data:`~gaitopt.study.grid_error.MAX_REFINE_LEVELS` levels."""
    if errors is None or errors.check_knots is None:
        return
    from gaitopt.study.summary import read_summary

    study_rows = read_summary(directory / SUMMARY_FILE)
    previous = directory / CHECK_DIR
    knots: tuple[int, ...] = errors.check_knots
    for level in range(1, MAX_REFINE_LEVELS + 1):
        folder = directory / refine_dir_name(level)
        points = errors.to_refine(level)
        if not points and not (folder / SUMMARY_FILE).exists():
            return
        # Rerunning a finished study: refine the same points again (they are kept).
        done = [p.row for p in errors.points if p.level >= level]
        rows = [p.row for p in points] + done
        knots = check_knots(knots)
        speeds = sorted({round(r.speed_m_min, 6) for r in rows if r.speed_mode == "fixed"})
        console.print(f"refinement grid {knots[0]}+{knots[1]} knots: {len(points)} points "
                      f"estimated above {100 * WITHIN:g} % on the grid before",
                      soft_wrap=True)
        if not speeds:  # only speed-free optima: solve them from the check grid's start speed
            speeds = [study.start * 60.0]
        spec = replace(study, speeds=tuple(float(f"{v:g}") / 60.0 for v in speeds),
                       variants=tuple(v for v in study.variants if v in {r.variant for r in rows}),
                       free_speed=any(r.speed_mode == "free" for r in rows),
                       base=study.base.replace(knots=knots), continuation=False)
        seeds = {p.key: previous / p.key for p in spec.points if (previous / p.key).exists()}
        run_with_progress(console, spec, folder, workers=workers, scheduler=scheduler,
                          seeds=seeds)
        errors = grid_error(directory, study_rows)
        if errors is None:
            return
        previous = folder


__all__ = ["make_spec", "parse_speeds", "parse_variants", "run_cost_study", "run_with_progress",
           "study_command", "sweep_command"]
