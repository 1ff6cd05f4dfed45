"""``gaitopt solve`` and ``gaitopt verify``: one gait, solved or checked."""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import Any

import click
from rich.table import Table

from gaitopt.cli.base import (
    USER_ERRORS,
    UserError,
    cli,
    control_model_option,
    cost_option,
    formulation_option,
    grid_choice,
    knot_spacing_option,
    make_console,
    min_knee_flexion_option,
    model_option,
    paper_grid_option,
    parse_free_or_value,
    parse_pair,
    phase_knots_option,
    resting_power_option,
)
from gaitopt.gait.formulations.select import (
    Formulation,
    biped_for,
    checked_sequence,
    formulation_of,
)
from gaitopt.gait.options.gait_options import (
    GAITS,
    TRANSCRIPTIONS,
    GaitOptions,
    GaitOptionsError,
    follows_model,
    validate_options,
)
from gaitopt.gait.options.model_defaults import MULTI_PHASE_KNOTS, options_for_model
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.options.preflight import refuse_unwalkable
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.gait.solve.staged import REFERENCE_SPEED, StageRecord, reference_speed
from gaitopt.gait.solve.torque_rate_fallback import fallback_line
from gaitopt.robot.biped import BipedStructureError
from gaitopt.units import format_speed, parse_speed


def _speed(text: str) -> float | None:
    """The ``--speed`` text in m/s, or None for free."""
    if text.strip().lower() == "free":
        return None
    try:
        return parse_speed(text)
    except ValueError as exc:
        raise UserError(f"--speed: {exc}") from None


#: Speeds (m/s) this far from 12 m/min are solved with multistart unless told otherwise
#: (15 m/min): the cold solves of 57 and 60 m/min end on the long-step branch, 19-25 % above
#: the sweep's optimum (docs/results/benchmarks-gait.md, "Multistart"). On the reference
#: biped (1 m legs); another model's is this at equal Froude number.
FAR_FROM_REFERENCE = 0.25


def multistart_default(speed: float | None, formulation: Formulation,
                       reference: float = REFERENCE_SPEED, far: float = FAR_FROM_REFERENCE
                       ) -> bool:
    """Whether ``gaitopt solve`` uses multistart when neither ``--multistart`` nor
    ``--no-multistart`` is given: for the paper's walk in reduced coordinates (where it was
    measured) at a given speed at least ``far`` (:data:`FAR_FROM_REFERENCE` on the reference
    biped) from the ``reference`` speed (12 m/min on the reference biped: the speed-free
    optimal walk starts there; a model's: :func:`gaitopt.gait.solve.staged.reference_speed`)."""
    return (formulation.traits.multistart_by_default and speed is not None
            and abs(speed - reference) >= far - 1e-12)


def read_sequence(path: Path) -> dict[str, Any]:
    """A contact sequence file (YAML): its data, checked for form (the model check comes with
    the options)."""
    from gaitopt.gait.sequence.contact_sequence import ContactSequenceError, sequence_from_dict
    from gaitopt.robot.loader import parse_yaml

    try:
        data = parse_yaml(path.read_text(encoding="utf-8"), source=str(path))
        sequence_from_dict(data)
    except OSError as exc:
        raise UserError(f"--contact-sequence {path}: {exc.strerror or exc}") from None
    except (ContactSequenceError, ValueError) as exc:
        raise UserError(f"--contact-sequence {path}: {exc}") from None
    return dict(data)


def speed_bounds(text: str) -> tuple[float, float]:
    """The ``--speed-bounds`` text ``LO,HI`` (each a speed with a unit, as ``--speed``) in m/s.

    Raises:
        UserError: not two speeds, or not ``0 < LO <= HI``.
    """
    parts = text.split(",")
    if len(parts) != 2:
        raise UserError(f"--speed-bounds: {text!r} must be two speeds LO,HI with units, e.g. "
                        "60m/min,400m/min")
    try:
        lo, hi = (parse_speed(p.strip()) for p in parts)
    except ValueError as exc:
        raise UserError(f"--speed-bounds: {exc}") from None
    if not 0.0 < lo <= hi:
        raise UserError(f"--speed-bounds: {text!r} must satisfy 0 < LO <= HI (the bounds of a "
                        "free speed)")
    return lo, hi


def _step(text: str) -> float | None:
    return parse_free_or_value(text, "--step-length", "m", "length")


def _step_time(text: str) -> float | None:
    return parse_free_or_value(text, "--step-time", "s", "time")


@cli.command("solve")
@model_option
@click.option("--speed", default=None,
              help="Average speed with a unit (12m/min, 0.2m/s) or 'free' (the optimal walk) "
                   "[default: the model's, at equal Froude number v^2/(g l): 12 m/min for the "
                   "five-link walk, 72.2 m/min for the seven-link heel-toe walk; "
                   "docs/walking.md].")
@click.option("--speed-bounds", "speed_bounds_text", default=None,
              help="LO,HI: the bounds of a free speed (--speed free), with units as --speed, "
                   "e.g. 60m/min,400m/min [default: the model's, 1.2-90 m/min on the "
                   "five-link biped]. A given --speed is never checked against them.")
@click.option("--step-length", default="free", show_default=True,
              help="Step length in m, or 'free'.")
@click.option("--step-time", default="free", show_default=True,
              help="Step time in s (step length / speed), or 'free'; not with --step-length.")
@click.option("--ankle/--no-ankle", default=True, show_default=True,
              help="Ankle torques at the tips on the ground.")
@click.option("--impulse/--no-impulse", default=None,
              help="Liftoff impulse along the lifting leg [default: on; off for --gait run, "
                   "which has no double support to push off from, and --impulse with it is "
                   "an error].")
@click.option("--single-support", type=float, default=None,
              help="Single-support fraction of the step time; 1 = no double support; a run's "
                   "stance share, fixed when given [default: 0.85; a run's is free in "
                   "0.2-0.95, docs/running.md].")
@click.option("--single-support-bounds", default=None,
              help="LO,HI: the single-support fraction free within these bounds, starting "
                   "from --single-support (needs --formulation full).")
@click.option("--free-fractions/--fixed-fractions", default=None,
              help="Every phase's share of the step free from the first stage, within half "
                   "to twice its given share (at most 0.95), starting from it (needs "
                   "--formulation full); or every share fixed. [default: a built-in "
                   "sequence of more than two phases (heel-toe) is solved with its shares "
                   "free, kept where it converges, costs less than the fixed shares on the "
                   "coarse grid and passes verify, else solved with them fixed as well; "
                   "docs/feet.md]")
@click.option("--stride", is_flag=True,
              help="Solve a stride: two steps (leg 1's, then leg 2's) periodic over two step "
                   "lengths, no leg swap assumed (for unequal legs); cost per metre of the "
                   "stride; full formulation (the default with it).")
@phase_knots_option
@knot_spacing_option("The knots of each phase: cosine-spaced (clustered at the events; "
                     "docs/walking.md section 6) or uniform.")
@paper_grid_option
@click.option("--transcription", type=click.Choice(list(TRANSCRIPTIONS)), default=None,
              help="hermite-simpson: DIRCOL's compressed form, the paper's NLP; "
                   "hermite-simpson-separated: the same scheme with the midpoint states as "
                   "variables (bounded like the knots), several times faster; see "
                   "docs/results/benchmarks-gait.md [default: "
                   f"{GaitOptions().transcription}; with --paper-grid "
                   f"{GaitOptions.paper().transcription}].")
@click.option("--periodic-controls/--periodic-states-only", default=True, show_default=True,
              help="Controls periodic as well as states (the paper), or states only.")
@click.option("--friction", type=float, default=None,
              help="Friction coefficient of an optional friction-cone constraint.")
@click.option("--unilateral-impulses/--paper-impulse-maps", default=True, show_default=True,
              help="Normal impulses on held tips >= 0 at the heel strike and the liftoff, or "
                   "the paper's maps as they are (the ground may pull a held tip).")
@formulation_option(
              help="reduced: the paper's coordinates (five-link biped); full: the whole "
                   "tree's q, qd with the held points as constraints (any model and contact "
                   "sequence, knees may straighten) [default: reduced for the five-link shape "
                   "and the walk, else full].", default=None)
@min_knee_flexion_option
@click.option("--gait", "gait_kind", type=click.Choice(list(GAITS)), default=None,
              help="The contact sequence: walk, run (stance then flight, no liftoff impulse, "
                   "the stance share free; docs/running.md) "
                   "or heel-toe (feet with heel and toe points, e.g. --model seven-link) "
                   "[default: what the model's feet allow: walk with one contact point per "
                   "leg, heel-toe with two].")
@click.option("--contact-sequence", "sequence_file",
              type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="A YAML file with a contact sequence (phases, events, anchors; "
                   "docs/formulations.md); replaces --gait.")
@cost_option(
              help="paper: torque squared per metre; work: mechanical cost of transport; "
                   "metabolic: positive/negative work efficiencies and a resting power "
                   "(docs/costs.md).")
@resting_power_option
@click.option("--regularization", type=float, default=0.0, show_default=True,
              help="Weight of an added mean squared torque (u / u_max)^2 term.")
@click.option("--torque-rate-time", type=click.FloatRange(min=0.0), default=0.0,
              show_default=True,
              help="Time tau in s of an added torque-rate term tau^2 int u'^2 dt in the cost "
                   "(prices torque changes faster than about 1 / (2 pi tau) Hz; "
                   "docs/feet.md).")
@control_model_option(
              help="Controls continuous at the heel strike and periodic (paper), or free to "
                   "jump at both events (jumps).")
@click.option("--mesh-tol", type=float, default=None,
              help="Refine the mesh until every interval's collocation error estimate is "
                   "<= TOL (e.g. 1e-4); default: the fixed grid --knots.")
@click.option("--accuracy", type=float, default=0.01, show_default=True,
              help="Refine the grid until the estimates of the cost, speed and step length are "
                   "within this relative accuracy (up to 3 times; exit status 3 if not "
                   "reached); with --knots the grid is kept and the estimate reported.")
@click.option("--clearance", type=float, default=None,
              help="Swing-tip clearance c in m: height >= c 4 s (1 - s) over single support "
                   "(a run's: over the stance); 0: height >= 0 only, the paper [default: 0; "
                   "a run on point feet 0.1 m per metre of leg, docs/running.md].")
@click.option("--clearance-profile", type=click.Choice(["parabola", "quartic"]),
              default="quartic", show_default=True,
              help="Clearance profile: c (4 s (1 - s))^2, or c 4 s (1 - s) (which also asks "
                   "for a least vertical tip velocity 4 c / T1 at liftoff and heel strike).")
@click.option("--compiled", is_flag=True, help="Compile the NLP to C (cached on disk).")
@click.option("--multistart/--no-multistart", default=None,
              help="Solve from every naive guess and, away from 12 m/min, by continuation in "
                   "speed; keep the lowest optimum (slower, fewer poor local optima) "
                   "[default: on at speeds 15 m/min or more from 12 m/min, where a single "
                   "cold start can end on a worse branch; off otherwise].")
@click.option("--warm-start", "warm_start", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="A gait file to start from (e.g. a neighbouring speed's "
                                 "gait); the cold path is the fallback.")
@click.option("--verify/--no-verify", "check", default=True, show_default=True,
              help="Run gaitopt verify's checks on the gait before writing it, keep the outcome "
                   "in the file (solver.verify) and exit with status 4 if a check fails "
                   "(0.2-1.5 s). An answer that fails is first solved again with a "
                   "torque-rate term (tau 0.02, 0.03, 0.05 s), kept where it passes "
                   "(solver.torque_rate_fallback; docs/running.md).")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              default=Path("gait.gait.json"), show_default=True, help="Gait file to write.")
def solve_command(model_name: str, speed: str | None, speed_bounds_text: str | None,
                  step_length: str, step_time: str, ankle: bool,
                  impulse: bool | None,
                  single_support: float | None, knots: str | None, knot_spacing: str | None,
                  paper_grid: bool,
                  transcription: str | None,
                  periodic_controls: bool, friction: float | None,
                  unilateral_impulses: bool, formulation: str | None,
                  min_knee_flexion: float | None, single_support_bounds: str | None,
                  free_fractions: bool | None, stride: bool,
                  gait_kind: str | None, sequence_file: Path | None, cost: str,
                  resting_power: float | None, regularization: float,
                  torque_rate_time: float,
                  control_model: str | None, mesh_tol: float | None, accuracy: float,
                  clearance: float | None, clearance_profile: str, compiled: bool,
                  multistart: bool | None,
                  warm_start: Path | None, check: bool, output: Path) -> None:
    """Solve the minimum-energy walking problem and write the gait file."""
    from gaitopt.analysis.plausible import Verifier
    from gaitopt.cli.gait_summary import summary_table
    from gaitopt.gait.api import as_model, solve_staged_run, warm_start_usable
    from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run

    console = make_console()
    model = as_model(model_name)
    start: Gait | None = None
    if warm_start is not None:
        try:
            start = Gait.load(warm_start)
        except GaitFileError as exc:
            raise UserError(f"--warm-start: {exc}") from None
    sequence = None if sequence_file is None else read_sequence(sequence_file)
    # Options not given keep the defaults that follow the model (options_for_model below).
    given: dict[str, Any] = {"speed": _speed(speed)} if speed is not None else {}
    given |= {"formulation": formulation} if formulation is not None else {}
    given |= {"gait": gait_kind} if gait_kind is not None else {}
    if speed_bounds_text is not None:
        given["speed_bounds"] = speed_bounds(speed_bounds_text)
    if single_support is not None:
        given["single_support_fraction"] = single_support
    run = gait_kind == "run" and sequence is None
    if impulse and run:
        raise UserError("--impulse with --gait run: a run leaves the ground from single "
                        "support into a flight, with no double support for a liftoff impulse "
                        "to act from; leave --impulse out (a run has none by default)")
    options = GaitOptions(
        contact_sequence=sequence,
        step_length=_step(step_length), step_time=_step_time(step_time),
        ankle=ankle, impulse=(not run) if impulse is None else impulse,
        **{**grid_choice(knots, control_model, paper_grid, knot_spacing, by_phase=True),
           **({"transcription": transcription} if transcription else {}),
           **given},
        periodic_controls=periodic_controls, friction=friction,
        unilateral_impulses=unilateral_impulses,
        cost=cost,  # type: ignore[arg-type]
        cost_regularization=regularization, torque_rate_time=torque_rate_time,
        mesh_tol=mesh_tol, accuracy=accuracy, swing_clearance=clearance,
        clearance_profile=clearance_profile,  # type: ignore[arg-type]
        free_phase_fractions=free_fractions, stride=stride)
    if resting_power is not None:
        options = options.replace(resting_power=resting_power)
    if single_support_bounds is not None:
        options = options.replace(
            single_support_fraction_bounds=parse_pair(single_support_bounds,
                                                 "--single-support-bounds"))
    if min_knee_flexion is not None:
        options = options.replace(min_stance_knee_flexion=min_knee_flexion)
    # knots left to the model: refine to --accuracy
    refine = follows_model(options.discretisation.knots)
    try:
        options = options_for_model(model, options)
        refuse_unwalkable(model, options)
        validate_options(options, biped_for(model, options))
        sequence_used = checked_sequence(model, options)
    except (GaitOptionsError, BipedStructureError) as exc:
        message = str(exc)  # the knots' form and names are --knots' (its text parsed alone)
        raise UserError(("--knots: " if message.startswith("discretisation.knots")
                         and knots is not None else "") + message) from None
    reference = reference_speed(model, options)
    if multistart is None:
        multistart = multistart_default(options.speed, formulation_of(options), reference,
                                        model_scale(model).speed(FAR_FROM_REFERENCE))
    options = options.replace(multistart=multistart)
    console.print(f"solving {options.variant} on model {model.name}: speed "
                  f"{'free' if options.speed is None else format_speed(options.speed)}, step "
                  f"length {'free' if options.step_length is None else f'{options.step_length} m'}"
                  + ("" if options.step_time is None else f", step time {options.step_time} s")
                  + f", {'+'.join(map(str, options.knots))} knots, control model "
                  f"{options.control_model}"
                  + (" (the paper's grid)" if options.paper_grid else "")
                  + f", {options.formulation} coordinates"
                  + (", a stride (two steps, no leg swap)" if options.stride else ""))

    if speed_bounds_text is not None and options.speed is not None:
        console.print("note: --speed-bounds bound a free speed (--speed free); the speed "
                      f"{format_speed(options.speed)} is fixed, so they play no part")
    if (start is None and not options.multistart
            and multistart_default(options.speed, formulation_of(options), reference,
                                   model_scale(model).speed(FAR_FROM_REFERENCE))):
        console.print(f"note: far from {format_speed(reference)} a cold solve can end in a "
                      "worse local optimum; "
                      "--multistart (the default here) also tries the continuation in speed "
                      "and keeps the best")
    per_step = (0 if sequence_used is None
                else len(sequence_used.phases) // sequence_used.steps)
    if (per_step > 2 and len(options.knots) == 2
            and tuple(options.knots) < MULTI_PHASE_KNOTS):
        console.print(f"note: a {per_step}-phase step on {options.knots[0]}+"
                      f"{options.knots[1]} knots is coarse; the heel-toe walk passes verify on "
                      f"{MULTI_PHASE_KNOTS[0]},{MULTI_PHASE_KNOTS[1]} or finer (--knots; "
                      "docs/feet.md)")
    if start is not None and not warm_start_usable(start, options):
        console.print(f"note: {warm_start} was solved with other ankle torques or another "
                      "single-support fraction; starting cold")

    def progress(stage: StageRecord) -> None:
        console.print("  stage " + stage.line())

    verifier = Verifier()
    try:
        solution = solve_staged_run(model, options, progress=progress, warm_start=start,
                                    compiled="codegen" if compiled else None,
                                    refine=refine, speed_given=speed is not None,
                                    plausible=verifier, smooth_rejected=check)
    except (GaitOptionsError, BipedStructureError) as exc:
        raise UserError(str(exc)) from None
    if not solution.success:
        from gaitopt.gait.solve.diagnose import diagnose

        diagnosis = diagnose(solution)
        console.print("FAILED: " + diagnosis.text())
        console.print(f"Largest constraint violation at that point {diagnosis.violation:.3g} "
                      "(in the constraints' own units). No gait file written.")
        sys.exit(1)
    try:
        gait = gait_from_run(solution)
    except MotionOutOfReachError as exc:
        console.print(f"FAILED after the last stage, which converged: {exc}. No gait file "
                      "written.")
        sys.exit(1)
    if solution.options.speed != options.speed and options.speed is not None:
        console.print(f"note: the solve at the model's default speed "
                      f"{format_speed(options.speed)} failed (its stages above); the gait "
                      f"walks at the slower default of the walk, "
                      f"{format_speed(solution.options.speed or 0.0)}; --speed chooses one")
    console.print(summary_table(gait, sequence_used))
    if solution.share_release is not None:
        shares = solution.share_release
        if "fixed_knots" in shares:  # the fixed shares solved on the coarse grid only
            costs = (f"fixed J {shares['fixed_cost']:.6g} and free J "
                     f"{shares['coarse_free_cost']:.6g} there; the answer's J "
                     f"{shares['free_cost']:.6g}")
        else:
            costs = f"fixed J {shares['fixed_cost']:.6g}" + (
                "" if shares["free_cost"] is None else f", free J {shares['free_cost']:.6g}")
        console.print(f"phase shares: {shares['why']} ({costs})", soft_wrap=True)
    if solution.torque_rate_fallback is not None:
        console.print(fallback_line(solution.torque_rate_fallback), soft_wrap=True)
    report = None
    if check:
        report = verifier.report(gait)
        gait = dataclasses.replace(gait, solver={**gait.solver, "verify": report.record()})
        console.print(f"verify: all {len(report.checks)} checks pass" if report.passed else
                      f"VERIFY FAILS {len(report.failed_ids)} of {len(report.checks)} checks: "
                      f"{report.failed_text()} (gaitopt verify {output} for the table)")
    gait.save(output)
    console.print(f"wrote {output}")
    record = gait.solver.get("accuracy", {})
    if record.get("within_target") is False:
        from gaitopt.gait.solve.refinement import MAX_ROUNDS, describe, diverging_text

        worst = (record.get("worst_estimate") or float("inf"),
                 record.get("worst_estimate_of", "cost"))
        console.print(f"NOT CONVERGED to {100 * record['target']:g} %: "
                      f"{describe(worst, record['target'])} after "
                      f"{record.get('refinements', 0)} of at most {MAX_ROUNDS} refinements"
                      f"{diverging_text(record)}; "
                      f"the gait file says so (gaitopt verify: accuracy.estimate). Try "
                      "--knots with more knots, --mesh-tol 1e-4, or --accuracy 0.02")
        sys.exit(3)
    if report is not None and not report.passed:
        sys.exit(4)


@cli.command("verify")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--tolerance", type=float, default=None,
              help="Scale every check's tolerance by this factor (default 1).")
@click.option("--json", "as_json", is_flag=True,
              help="Print the report as JSON (checks by stable id) instead of a table.")
def verify_command(file: Path, tolerance: float | None, as_json: bool) -> None:
    """Check a saved gait independently of the solver (exit status 1 if a check fails)."""
    import json

    from gaitopt.analysis.verify import UnknownStatesError, verify_gait

    if tolerance is not None and not (math.isfinite(tolerance) and tolerance > 0):
        raise UserError(f"--tolerance: got {tolerance:g}; allowed: a number > 0")
    console = make_console()
    try:
        gait = Gait.load(file)
        report = verify_gait(gait, tolerance_scale=tolerance or 1.0)
    except (GaitFileError, UnknownStatesError) as exc:
        raise UserError(str(exc)) from None
    if as_json:
        click.echo(json.dumps({"file": str(file), **report.to_dict()}, indent=1))
        if not report.passed:
            sys.exit(1)
        return
    table = Table(title=f"verify {file}")
    for col in ("id", "check", "value", "limit", "result", "worst at"):
        table.add_column(col)
    for c in report.checks:
        table.add_row(c.id, c.name, f"{c.value:.3g}", c.limit_text, "ok" if c.passed else "FAIL",
                      c.where)
    console.print(table)
    if report.passed:
        console.print(f"all {len(report.checks)} checks passed")
    else:
        failed = report.failed_ids
        console.print(f"{len(failed)} check(s) FAILED: {', '.join(failed)}")
        sys.exit(1)


USER_ERRORS_HERE = (GaitOptionsError, BipedStructureError, GaitFileError)
__all__ = ["USER_ERRORS", "USER_ERRORS_HERE", "solve_command", "verify_command"]
