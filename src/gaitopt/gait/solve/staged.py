"""Solving the walking problem robustly from a naive start: staged continuation.

(One concept, kept whole at about 540 lines, a tenth of them this docstring: the stages are
methods of one run that share its record of stages, results and grid costs.)

The paper's authors climbed to the optimum by hand through sub-problems. gaitopt does it by
itself, in stages that each warm-start the next (primal values and multipliers). Stages 1-3
and the switch of control model are data (:mod:`gaitopt.gait.solve.stages`:
:data:`~gaitopt.gait.solve.stages.CONTACT_STAGES`, then
:data:`~gaitopt.gait.solve.stages.COARSE_COMPLETION`:
:data:`~gaitopt.gait.solve.stages.CONTROL_MODEL_STAGE`
and :data:`~gaitopt.gait.solve.stages.RELEASES`) that one loop each walks:

1. ``relaxed contact``: the coarse grid (at most the paper's 8 + 5 knots) at the target speed
   (12 m/min when the speed is free) with no liftoff impulse, the unilateral contact
   conditions relaxed (normal forces and impulses may be negative), from the geometric guess
   of :mod:`gaitopt.gait.guess.naive`, with IPOPT's adaptive barrier update
   (:data:`~gaitopt.gait.solve.stages.COLD_START_OPTIONS`); the ankle torques held at zero;
2. ``enforced contact``: the same with the contact conditions enforced (the paper's two-stage
   process);
3. ``ankle torques free``, ``liftoff impulse free`` (impulse variants), ``phase fractions
   free`` (when some are free) and ``speed free`` (the optimal walk): what was held so far
   is released one at a time; starting from the no-impulse gait keeps the impulse variants
   from stopping in worse local minima than the no-impulse gait;
4. ``target grid``: the requested grid, if finer, from the coarse solution interpolated
   (started with a small barrier, :data:`PRIMAL_WARM_OPTIONS`, and solved with a
   limited-memory Hessian, :data:`~gaitopt.gait.solve.stages.FINE_STAGE_OPTIONS`);
5. ``mesh refinement N`` (with ``mesh_tol``): every interval whose collocation error estimate
   exceeds ``mesh_tol`` is split (:func:`gaitopt.ocp.refined_mesh`) and the problem solved
   again from the last solution, until every estimate is within ``mesh_tol``; then ``mesh
   check (halved)``: every interval halved, for the cost error estimate. The rounds work on
   the :class:`~gaitopt.ocp.Transcription` and :class:`~gaitopt.ocp.Result` only.

Stages 1-2 (and the continuation in speed) always solve the paper's control model
(:data:`COLD_CONTROL_MODEL`), from which IPOPT starts reliably; with another control model a
stage ``control model jumps`` then re-solves the coarse problem in it from that solution's
values (the paper's optimum is feasible for the jumps model, which only drops the control
linkages). From the naive guess the jumps model's first stage failed after 507 iterations
(8.5 s) at 12 m/min, where the paper's took 24.

If stage 1 or 2 fails, the same is tried from guesses with shorter and longer steps, then by
continuation in speed from the reference speed (12 m/min). With ``multistart`` all three
guesses and (away from 12 m/min) the continuation in speed are solved; every distinct coarse
optimum among them (:func:`distinct`) is taken through the remaining stages (its stages named
``start i/n: ...``) and the lowest final optimum is kept: the problem has several local optima
(a long-step and a short-step branch at high speed), a single cold start can end on the worse
one, and which branch is lower can change between the coarse problem of the cold stages (the
paper's control model, ankle torques held) and the requested one (at 60 m/min on 16 + 6
knots the long-step branch is 0.06 % lower there and 19 % higher in the end). Given a warm start
(a neighbouring gait), the target problem is solved from it directly and the cold path is the
fallback.
Every stage is reported through ``progress`` and kept in the run, so a failure says which
stage failed and why.

Transcriptions (NLP and IPOPT solver) are built once per process for each problem structure
and reused (:mod:`gaitopt.gait.solve.transcriptions`): speed, step length and impulse enter through
parameter bounds only. What a solve returns inside gaitopt is in
:mod:`gaitopt.gait.solve.staged_run`; users get its :class:`~gaitopt.gait.record.file.Gait`.
"""

from __future__ import annotations

import dataclasses
import time
from math import nan
from typing import Any

import numpy as np

from gaitopt.dynamics.reduced import ReachError
from gaitopt.gait.formulations.select import (
    biped_for,
    checked_sequence,
    formulation_of,
    stage_bounds,
)
from gaitopt.gait.formulations.step_parameters import (
    FRACTION,
    IMPULSE,
    SPEED,
    STEP_LENGTH,
    Relaxation,
    parameter_bounds,
    with_step_time,
)
from gaitopt.gait.guess.naive import (
    default_running_step,
    default_step_length,
)
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.options.model_defaults import default_gait, default_speed, options_for_model
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.solve.check_grid import check_knots
from gaitopt.gait.solve.cost_continuation import (
    CHECK_HELD_KINDS,
    check_holds_step,
    check_smoothings,
    climb_ladder,
    continues_from_paper,
)
from gaitopt.gait.solve.staged_run import (
    CHECK_FROM_VALUES_STAGE,
    CHECK_GRID_STAGE,
    ProgressFn,
    StagedRun,
    StageRecord,
    as_failed,
    best_of,
    converged_or_failed,
    result_guess,
)
from gaitopt.gait.solve.stages import (
    ANKLES,
    CHECK_REGRID_MAX_ITER,
    COARSE_COMPLETION,
    COLD_CONTROL_MODEL,
    CONTACT_STAGES,
    MONOTONE_RESTART_STAGE,
    PRIMAL_WARM_OPTIONS,
    RELEASES,
    WARM_START_STAGE,
    check_grid_options,
    coarse_knots,
    fine_grid_options,
    fine_stage_options,
    held_ankles,
    held_bounds,
    held_stage_options,
    restart_options,
    sequence_kind,
)
from gaitopt.gait.solve.transcriptions import (
    Grid,
    evaluation_mode,
    grid_knots,
    is_mesh,
    target_grid,
    transcription_for,
    warm_start_grid,
)
from gaitopt.ocp import Guess, ProblemError, Result, WarmStart, refined_mesh
from gaitopt.ocp.mesh import split_intervals
from gaitopt.ocp.regrid import regridded
from gaitopt.robot.model import RobotModel

#: Reference speed (m/s) of the reference biped (the five-link's 1 m legs) for the
#: continuation fallback and the start of a speed-free solve: the paper's optimal 12 m/min.
#: A model's is its default speed (:func:`reference_speed`), equal to this for the five-link
#: walk.
REFERENCE_SPEED = 0.2
#: Largest speed change (m/s) between two continuation steps on the reference biped; a model's
#: is this at equal Froude number (:meth:`~gaitopt.gait.options.model_scale.ModelScale.speed`).
SPEED_STEP = 0.1
#: Most refinement rounds after the fixed-grid stages, and most knots per phase they may make
#: (the bound of ``GaitOptions.knots``).
MAX_REFINEMENTS = 6
MAX_REFINED_KNOTS = 400
#: The moves to another grid that start IPOPT from the last solution's values AND its
#: multipliers mapped onto the new grid (:mod:`gaitopt.ocp.regrid`), with the transcription's
#: warm-start options and :data:`REGRID_OPTIONS` over them, by contact sequence kind
#: (:func:`~gaitopt.gait.solve.stages.sequence_kind`): ``"target"`` (the target grid from the
#: coarse solution), ``"check"`` (the check grid from the target grid's), ``"refinement"``
#: (mesh refinement rounds); other moves start from the values only. Measured by
#: bench/regrid.py (docs/results/benchmarks-gait.md): the heel-toe walk's check grid took 112
#: instead of 188 iterations at 12 m/min and 31 instead of 63 at 36 m/min (seven-link,
#: 24 + 16 knots),
#: the same optima; on the two-phase walk it saved nothing, and the target grid move, which
#: saved a fifth of that stage's iterations on the five-link walks, sent the heel-toe walk to
#: a 0.5 % dearer optimum.
REGRID_MOVES: dict[str, frozenset[str]] = {"heel-toe": frozenset({"check"})}
#: The initial barrier of the mapped starts: 1e-4, as a start from values only. With the
#: transcription's 1e-6 the heel-toe walk's check grid took 58 iterations at 12 m/min but to
#: a 1.8 % dearer optimum.
REGRID_OPTIONS: dict[str, Any] = {"ipopt.mu_init": 1e-4}


def reference_speed(model: RobotModel, options: GaitOptions) -> float:
    """The speed (m/s) a speed-free solve starts from and the continuation in speed starts
    at: the model's default speed of the gait (:func:`~gaitopt.gait.options.model_defaults.
    default_speed`; of the gait its feet allow for a given contact sequence), which is
    :data:`REFERENCE_SPEED` for the five-link walk."""
    gait = str(options.gait)
    if options.contact_sequence is not None:
        try:
            gait = default_gait(model)
        except GaitOptionsError:
            gait = "walk"
    return default_speed(model, gait)


def step_held_bounds(options: GaitOptions, result: Result) -> dict[str, Any]:
    """The parameter bounds of ``options`` with the step length (m) and the speed (m/s) held
    at ``result``'s values (a stage on another grid or with another smoothing started from
    ``result``, whose release follows)."""
    held = dict(parameter_bounds(options))
    for key in ("step_length", "speed"):
        held[key] = (result.parameters[key], result.parameters[key])
    return held


def holds_free_shares(options: GaitOptions) -> bool:
    """Whether the check grid of ``options`` holds the step length and speed first
    (:meth:`_Run.check`) because the phase shares are free on a contact sequence of
    :data:`~gaitopt.gait.solve.cost_continuation.CHECK_HELD_KINDS` (the heel-toe walk).

    Measured 2026-12-03 (docs/feet.md, "Free phase shares by default"), the seven-link with
    the speed free and the shares free: from the 24 + 18 optimum (J 1707.75 at 58.4 m/min) the
    check grid with everything free wandered off (J 3618 at 67.6 m/min, violation 0.12, at the
    120 s limit; from the other start 2755 at 75.4 m/min); held, then free, it converged in
    13 + 7 iterations at J 1707.79 and the same speed."""
    return (options.free_phase_fractions is True
            and sequence_kind(options) in CHECK_HELD_KINDS)


class _Run:
    """One call of :func:`solve_walking`: runs stages and records them."""

    def __init__(self, model: RobotModel, options: GaitOptions, progress: ProgressFn | None,
                 compiled: str | None, stage_seconds: float | None = None,
                 check_cold: bool = True) -> None:
        self.model, self.options, self.progress, self.compiled = model, options, progress, \
            compiled
        #: Whether :meth:`refine` solves the check grid after the target grid.
        self.check_cold = check_cold
        #: IPOPT's wall-time limit (s) of each stage (``ipopt.max_wall_time``), or None.
        self.stage_seconds = stage_seconds
        #: The model's size (:mod:`gaitopt.gait.options.model_scale`) and reference speed (m/s).
        self.scale = model_scale(model)
        self.reference_speed = reference_speed(model, options)
        self.stages: list[StageRecord] = []
        #: Put before every stage name (the start being completed, with several).
        self.prefix = ""
        self.results: list[Result] = []
        self.named_results: list[tuple[str, Result]] = []
        self.grid_costs: list[tuple[tuple[int, ...], float]] = []
        #: Naive starts no leg could reach: (step length m, longest leg reach m, why).
        self.unplaced: list[tuple[float, float, str]] = []
        #: The free phase fractions' parameters -> first guesses (held by the cold stages).
        self.fractions = formulation_of(options).fraction_guesses(model, options)

    def stage(self, name: str, knots: Grid, relax: Relaxation,
              guess: Guess | Result | WarmStart, bounds: dict[str, Any], *,
              hold_ankles: bool = False, solver_options: dict[str, Any] | None = None,
              problem: GaitOptions | None = None,
              warm_start_options: dict[str, Any] | None = None) -> Result:
        """Solve one stage; a Result guess also passes its multipliers to IPOPT.
        ``hold_ankles`` bounds the ankle torques to zero (the no-ankle gait);
        ``solver_options`` are merged over the transcription's (``warm_start_options`` over
        its warm-start options); ``problem`` replaces the run's options for this stage's NLP
        (another cost, say)."""
        tr = transcription_for(self.model, problem or self.options, knots,
                               compiled=self.compiled)
        if is_mesh(knots) or tuple(knots) != coarse_knots(self.options):
            solver_options = {**fine_grid_options(self.options), **(solver_options or {})}
        if self.stage_seconds is not None:
            solver_options = {**(solver_options or {}),
                              "ipopt.max_wall_time": float(self.stage_seconds)}
        start = time.perf_counter()
        nlp_bounds = with_step_time(stage_bounds(tr, relax, self.options), self.options)
        if hold_ankles:
            nlp_bounds = held_ankles(self.model, tr, nlp_bounds)
        result = tr.solve(guess, bounds=nlp_bounds, parameters=bounds, options=solver_options,
                          warm_start_multipliers=isinstance(guess, Result | WarmStart),
                          warm_start_options=warm_start_options)
        result = converged_or_failed(result)
        full = (relax == Relaxation() and not hold_ankles and problem in (None, self.options)
                and dict(bounds) == dict(parameter_bounds(self.options)))
        report = StageRecord(
            name=self.prefix + name, knots=grid_knots(knots, self.options),
            status=result.status,
            success=result.success, iterations=result.iterations, objective=result.objective,
            violation=result.constraint_violation, wall_time_s=time.perf_counter() - start,
            parameters=dict(result.parameters), full_problem=full)
        self.stages.append(report)
        self.results.append(result)
        self.named_results.append((self.prefix + name, result))
        if full and result.success:
            self.grid_costs.append((tuple(m.size for m in result.mesh), result.objective))
        if self.progress is not None:
            self.progress(report)
        return result

    def scaled(self, relax: Relaxation) -> Relaxation:
        """A relaxation of the reference biped (N, N s) carried over to the model as a force
        and an impulse (zero stays zero)."""
        return Relaxation(force=self.scale.force(relax.force),
                          impulse=self.scale.impulse(relax.impulse))

    def cold(self, speed: float) -> Result | None:
        """Stages 1-2 on the coarse grid at ``speed`` without impulse, from naive guesses
        (the requested step length, or a speed-based guess and two others): the first that
        converges."""
        found = self.cold_starts(speed, every_start=False)
        return found[0] if found else None

    def cold_starts(self, speed: float, *, every_start: bool) -> list[Result]:
        """The converged results of :meth:`cold`'s naive guesses: the first one, or with
        ``every_start`` all of them."""
        o, coarse = self.options, coarse_knots(self.options)
        formulation = formulation_of(o)
        biped = formulation.biped(self.model)
        r_max = (0.0 if biped is None else
                 min(leg.reach(-o.min_stance_knee_flexion) for leg in biped.legs))
        held = {spec.frees for spec in RELEASES if spec.frees and spec.runs(o)}
        bounds = held_bounds(o, held, speed, fractions=self.fractions)
        bounds[SPEED] = (speed, speed)  # also when the speed is given: continuation
        if o.step_length is not None:
            steps = [o.step_length]
        elif o.step_time is not None:
            steps = [o.step_time * speed]
        else:
            default = default_running_step if o.gait == "run" else default_step_length
            steps = [default(speed, self.scale) * f for f in (1.0, 0.7, 1.4)]
        found: list[Result] = []
        for step0 in steps:
            try:
                guess = formulation.cold_guess(self.model, o, speed=speed, step_length=step0,
                                               knots=coarse, r_max=r_max)
            except ReachError as exc:  # this start puts a leg beyond its reach: the next
                self.unplaced.append((step0, r_max, str(exc)))
                continue
            start = guess.to_ocp()
            if self.fractions:  # free fractions start at their guesses
                start = Guess(phases=start.phases,
                              parameters={**start.parameters, **self.fractions})
            result: Guess | Result = start
            for spec in CONTACT_STAGES:
                result = self.stage(spec.name, coarse, self.scaled(spec.relax), result, bounds,
                                    hold_ankles=ANKLES in held,
                                    solver_options=spec.solver_options,
                                    warm_start_options=spec.warm_start_options(o),
                                    problem=self.cold_options)
                if not result.success:
                    break
            else:
                assert isinstance(result, Result)
                found.append(result)
                if not every_start:
                    break
        return found

    @property
    def cold_options(self) -> GaitOptions:
        """The problem of the cold stages: the run's with :data:`COLD_CONTROL_MODEL`."""
        if self.options.control_model == COLD_CONTROL_MODEL:
            return self.options
        return self.options.replace(control_model=COLD_CONTROL_MODEL)

    def complete(self, coarse: Result | None) -> Result | None:
        """A coarse solution of the cold stages through the rest: :meth:`release` (the
        requested control model and the releases) and the requested grid (None for None)."""
        if coarse is None:
            return None
        outcome = self.release(coarse)
        return self.refine(outcome) if outcome.success else outcome

    def best_completion(self, starts: list[Result]) -> Result | None:
        """:meth:`complete` each of ``starts`` (their stages named ``start i/n: ...`` when
        there are several) and keep the converged one of lowest cost; the grid costs the
        cost error estimate reads are the kept one's. The last outcome if none converged."""
        if len(starts) <= 1:
            return self.complete(starts[0] if starts else None)
        before = list(self.grid_costs)
        done: list[tuple[Result | None, list[tuple[tuple[int, ...], float]]]] = []
        for i, start in enumerate(starts):
            self.prefix = f"start {i + 1}/{len(starts)}: "
            mark = len(self.grid_costs)
            outcome = self.complete(start)
            done.append((outcome, self.grid_costs[mark:]))
        self.prefix = ""
        best = best_of([outcome for outcome, _ in done])
        if best is None:
            return done[-1][0]
        self.grid_costs = before + next(grids for outcome, grids in done if outcome is best)
        return best

    def release(self, result: Result) -> Result:
        """The coarse solution of the cold stages through the :data:`COARSE_COMPLETION`
        stages that run: the requested control model (from the values only), then what the
        cold stages held freed one stage at a time. Each stage holds what the later ones
        free, at the values of ``result`` or of the last ``values_only`` stage (the impulse
        at 0, the ankle torques at zero)."""
        o, coarse = self.options, coarse_knots(self.options)
        stages = [spec for spec in COARSE_COMPLETION if spec.runs(o)]
        start = result
        for i, spec in enumerate(stages):
            held = {later.frees for later in stages[i + 1:] if later.frees}
            guess = result_guess(result) if spec.values_only else result
            result = self.stage(spec.title(o), coarse, spec.relax, guess,
                                held_bounds(o, held, start.parameters[SPEED], start,
                                            self.fractions),
                                hold_ankles=ANKLES in held, solver_options=spec.solver_options,
                                warm_start_options=spec.warm_start_options(o))
            if not result.success:
                return result
            if spec.values_only:
                start = result
        return result

    def refine(self, result: Result) -> Result:
        """The requested grid, when finer than the coarse one: first with the step length and
        speed held at the coarse solution's (a fine grid started from a coarse solution with
        them free can wander to a far worse local optimum), then released. Without
        ``mesh_tol``, then :meth:`check`: the same problem on the check grid, for the cost
        error estimate; the target grid's solution is the answer (not when the run was made
        with ``check_cold=False``)."""
        o = self.options
        if tuple(o.knots) == coarse_knots(o) and o.knot_spacing == "uniform":
            return result
        fine = self.on_grid("target grid", target_grid(self.model, o), result)
        if fine.success and o.mesh_tol is None and self.check_cold:
            self.check(fine)
        return fine

    def check(self, result: Result, start: WarmStart | None = None) -> None:
        """Stage ``check grid``: the problem on :func:`~gaitopt.gait.solve.check_grid.check_knots`
        of the requested knots (same spacing), everything free, from ``result``'s values and
        multipliers, with the target grid's Hessian (quasi-Newton in the compressed form, whose
        exact Hessian takes seconds to build). Its cost (kept in ``grid_costs`` after the
        answer's) is what the cost error estimate compares with
        (:mod:`gaitopt.gait.solve.accuracy`); a check that fails leaves the answer without that
        estimate, never changes it. ``start``: a solution of this check grid's NLP (a gait
        file's, :func:`gaitopt.gait.solve.warm_accuracy.check_point`) to restart from instead,
        with its multipliers and the warm-start options of the transcription, where it
        fits. Otherwise, for a cost with kinks on the heel-toe walk: at a smoothing of at most
        the ladder's second rung (the seven-link's 0.16 W,
        :func:`~gaitopt.gait.solve.cost_continuation.check_holds_step`) a first stage
        ``check grid, step held`` with the step length and speed held at ``result``'s
        (:func:`step_held_bounds`), then the stage that frees them; at a finer one the
        :func:`~gaitopt.gait.solve.cost_continuation.check_smoothings` first (stages ``check
        grid, eps E W``, everything free); every stage with the transcription's warm-start
        barrier (1e-6) instead of :data:`REGRID_OPTIONS`. The free phase shares of the
        heel-toe walk hold the step too, with any cost that climbs no ladder
        (:func:`holds_free_shares`). A ``check grid`` stage started straight from the mapped
        point (no stage before it) stops after :data:`~gaitopt.gait.solve.stages.
        CHECK_REGRID_MAX_ITER` iterations and, where it did not converge, the check grid is
        solved from ``result``'s values only (stage ``check grid, from values``).
        """
        o = self.options
        grid = target_grid(self.model, o.replace(knots=check_knots(o.knots)))
        if start is not None:
            tr = transcription_for(self.model, o, grid, compiled=self.compiled)
            if start.fits(tr.layout, tr.method, tr.nlp.lbg.size):
                self.stage("check grid", grid, Relaxation(), start, parameter_bounds(o),
                           solver_options=check_grid_options(o))
                return
        point: Result | WarmStart = self.grid_start(grid, result, "check")
        ladder = check_smoothings(o, self.scale)
        warm: dict[str, Any] | None = None if ladder else REGRID_OPTIONS
        for eps in ladder:
            point = self.stage(f"check grid, eps {eps:.3g} W", grid, Relaxation(), point,
                               parameter_bounds(o), solver_options=check_grid_options(o),
                               problem=o.replace(cost_smoothing=eps), warm_start_options=warm)
            if not point.success:
                return
        if check_holds_step(o, self.scale) or (not ladder and holds_free_shares(o)):
            point = self.stage("check grid, step held", grid, Relaxation(), point,
                               step_held_bounds(o, result),
                               solver_options=check_grid_options(o))
            if not point.success:
                return
            warm = None
        # Straight from the mapped start: bounded, then from the values only (a mapped start
        # that runs away; CHECK_REGRID_MAX_ITER).
        mapped = isinstance(point, WarmStart)
        bound = ({"ipopt.max_iter": min(o.max_iter, CHECK_REGRID_MAX_ITER)} if mapped else {})
        checked = self.stage(CHECK_GRID_STAGE, grid, Relaxation(), point, parameter_bounds(o),
                             solver_options={**check_grid_options(o), **bound},
                             warm_start_options=warm)
        if mapped and not checked.success:
            self.stage(CHECK_FROM_VALUES_STAGE, grid, Relaxation(), result,
                       parameter_bounds(o), solver_options=check_grid_options(o))

    def grid_start(self, grid: Grid, result: Result, move: str) -> Result | WarmStart:
        """The start on ``grid`` from ``result`` (another grid): for a ``move`` in
        :data:`REGRID_MOVES` its values and multipliers mapped onto ``grid``
        (:func:`gaitopt.ocp.regrid.regridded`), else ``result`` (its values only)."""
        o = self.options
        if move not in REGRID_MOVES.get(sequence_kind(o), frozenset()):
            return result
        tr = transcription_for(self.model, o, grid, compiled=self.compiled)
        try:
            return regridded(tr, result)
        except ProblemError:  # a result of another problem: its values only, as before
            return result

    def on_grid(self, name: str, grid: Grid, result: Result, move: str = "target") -> Result:
        """Solve on ``grid`` from ``result`` (another grid; ``move`` as in
        :data:`REGRID_MOVES`): the step length and speed held at ``result``'s (to a looser
        tolerance when a release follows, :func:`~gaitopt.gait.solve.stages.held_stage_options`),
        then (stage ``name, all free``) released."""
        o = self.options
        held = step_held_bounds(o, result)
        all_fixed = o.speed is not None and (o.step_length is not None or
                                             o.step_time is not None)
        fine = self.stage(name, grid, Relaxation(), self.grid_start(grid, result, move), held,
                          solver_options=held_stage_options(o, released=not all_fixed),
                          warm_start_options=REGRID_OPTIONS)
        if not fine.success or all_fixed:
            return fine
        free = self.stage(f"{name}, all free", grid, Relaxation(), fine,
                          parameter_bounds(o), solver_options=fine_stage_options(o))
        if free.success or not fine_stage_options(o):
            return free
        # The quasi-Newton stage can stall at IPOPT's acceptable level with a violation above
        # ACCEPTABLE_VIOLATION (16 + 6 knots, ankle torques, 36 m/min): once more, from the
        # held stage, with the exact Hessian.
        return self.stage(f"{name}, all free (exact Hessian)", grid, Relaxation(), fine,
                          parameter_bounds(o))

    def refine_mesh(self, result: Result) -> Result:
        """Refinement rounds (``mesh_tol``): split the intervals whose error estimate exceeds
        the tolerance and solve again from ``result`` until every estimate is within it (at
        most :data:`MAX_REFINEMENTS` rounds and :data:`MAX_REFINED_KNOTS` knots per phase);
        then one round on that mesh with every interval halved, whose solution is the
        answer and whose cost change from the mesh before is the cost error estimate
        (:mod:`gaitopt.gait.solve.accuracy`). Successive adaptive meshes differ by a few knots
        only, so their cost change says little about the remaining error."""
        tol = self.options.mesh_tol
        if tol is None:
            return result
        for round_ in range(1, MAX_REFINEMENTS + 1):
            if result.max_error <= tol:
                break
            mesh = refined_mesh(result, tol)
            if max(m.size for m in mesh) > MAX_REFINED_KNOTS:
                break
            result = self.on_grid(f"mesh refinement {round_}", mesh, result, "refinement")
            if not result.success:
                return result
        halved = tuple(split_intervals(m, np.full(m.size - 1, 2, dtype=np.int64))
                       for m in result.mesh)
        if max(m.size for m in halved) > MAX_REFINED_KNOTS:
            return result
        return self.on_grid("mesh check (halved)", halved, result, "refinement")

    def speed_continuation(self, target: float) -> Result | None:
        """Solve at the reference speed, then step toward ``target``."""
        o = self.options
        v_ref, v_step = self.reference_speed, self.scale.speed(SPEED_STEP)
        current = self.cold(v_ref)
        if current is None:
            return None
        speeds = np.linspace(v_ref, target, int(np.ceil(abs(target - v_ref) / v_step)) + 1)[1:]
        bounds = held_bounds(o, {IMPULSE, FRACTION}, v_ref,
                             fractions=self.fractions)
        for v in speeds:
            b = dict(bounds)
            b["speed"] = (float(v), float(v))
            current = self.stage(f"continuation {v * 60:.1f} m/min", coarse_knots(o),
                                 Relaxation(), current, b, hold_ankles=o.ankle,
                                 problem=self.cold_options)
            if not current.success:
                return None
        return current

    def other_cost(self) -> Result | None:
        """A cost other than the paper's, by continuation: the whole solve with the paper's
        cost first (its stages reported with the prefix ``paper cost:``), then the cost
        asked for from that optimum, first with coarser smoothings of the positive parts
        (:func:`~gaitopt.gait.solve.cost_continuation.climb_ladder`), then (without
        ``mesh_tol``, on a grid other than the coarse one) :meth:`check`, for the cost error
        estimate: without it the accuracy rule solved the check grid's knots, then their
        own check grid (docs/feet.md). None if the paper solve fails."""
        o = self.options
        paper = o.replace(cost="paper", cost_regularization=0.0)

        def report(stage: StageRecord) -> None:
            stage = dataclasses.replace(stage, name=f"paper cost: {stage.name}")
            self.stages.append(stage)
            if self.progress is not None:
                self.progress(stage)

        start = solve_walking(self.model, paper, progress=report, compiled=self.compiled)
        if not start.success:
            self.results.append(start.result)
            return None

        def stage(name: str, problem: GaitOptions, guess: Guess | Result,
                  solver_options: dict[str, Any]) -> Result:
            return self.stage(name, target_grid(self.model, o), Relaxation(), guess,
                              parameter_bounds(o), solver_options=solver_options,
                              problem=problem)

        result = climb_ladder(o, result_guess(start.result), self.scale, stage)
        uniform_coarse = tuple(o.knots) == coarse_knots(o) and o.knot_spacing == "uniform"
        if result.success and o.mesh_tol is None and not uniform_coarse:
            self.check(result)  # the cost error estimate, as the paper cost's refine() has
        return result

    def final(self) -> Result:
        """The last stage's outcome, or, if its values are not finite (a diverged solve),
        the last stage whose values are, marked failed."""
        for result in reversed(self.results):
            if np.all(np.isfinite(result.w)):
                if result is not self.results[-1]:
                    return as_failed(result, self.results[-1])
                return result
        return self.results[-1]


def solve_walking(model: RobotModel, options: GaitOptions, *,
                  warm_start: Guess | Result | WarmStart | None = None,
                  progress: ProgressFn | None = None,
                  compiled: str | None = None,
                  check_warm_start: bool = False,
                  check_start: WarmStart | None = None,
                  stage_seconds: float | None = None,
                  warm_start_options: dict[str, Any] | None = None,
                  check_cold: bool = True, adaptive_restart: bool = False) -> StagedRun:
    """Solve the walking problem (see the module docstring). Never raises for a failed solve:
    the returned (internal) :class:`~gaitopt.gait.solve.staged_run.StagedRun` says whether it
    succeeded and which stage failed.

    ``warm_start_options``: IPOPT options of stage ``warm start`` merged over the
    transcription's warm-start options, for a ``warm_start`` with multipliers
    (:data:`REGRID_OPTIONS` for one mapped from another grid,
    :func:`gaitopt.gait.api.regridded_point`). With ``adaptive_restart`` (and without
    them), a ``warm_start`` that restarts IPOPT with its multipliers on the same grid is
    first solved with the adaptive barrier (:func:`~gaitopt.gait.solve.stages.
    restart_options`, at most :data:`~gaitopt.gait.solve.stages.RESTART_MAX_ITER`
    iterations) and, if that does not converge, again from the same start with the monotone
    one (stage ``warm start, monotone barrier``,
    :data:`~gaitopt.gait.solve.stages.MONOTONE_RESTART_STAGE`): for a solution of this
    problem at another speed (a gait file's, :func:`gaitopt.gait.api.solve_staged_run`; a
    sweep neighbour's, :data:`gaitopt.study.worker.ADAPTIVE_STARTS`). Not for a secant
    prediction, a start mapped from another grid or the solution of another cost, where it
    was measured to fail, nor for the solution of this very problem (a refinement's
    restart), which the monotone barrier confirms where it is (the adaptive one moved the
    step length of a flat optimum by 2e-5).

    ``check_warm_start``: after a warm start that converged, solve the check grid too (stage
    ``check grid``), so the answer carries its cost error estimate
    (:mod:`gaitopt.gait.solve.refinement` solves each finer grid so), restarted from
    ``check_start`` where it fits (:meth:`_Run.check`). ``stage_seconds``: a wall-time
    limit (s) of each IPOPT stage (a stage that reaches it fails), or None.
    ``check_cold``: after a cold (or continued) solve's target grid, solve its check grid
    for the cost error estimate (without ``mesh_tol``); False leaves the answer without the
    estimate, as a warm start without ``check_warm_start`` (a sweep whose points are
    estimated by a sweep of their own, :mod:`gaitopt.study.grid_error`).

    Raises:
        GaitOptionsError: invalid options, or a step so long that no naive start can place
            the legs (nothing was solved; the message says what to change).
    """
    options = options_for_model(model, options)
    validate_options(options, biped_for(model, options))
    checked_sequence(model, options)
    evaluation_mode(options, compiled)  # refuses a compilation that would take too long
    start = time.perf_counter()
    run = _Run(model, options, progress, compiled, stage_seconds, check_cold=check_cold)
    result: Result | None = None
    if warm_start is not None:
        grid = warm_start_grid(model, options, warm_start)

        def restart(name: str, barrier_options: dict[str, Any] | None) -> Result:
            return run.stage(name, grid, Relaxation(), warm_start, parameter_bounds(options),
                             solver_options=PRIMAL_WARM_OPTIONS,
                             warm_start_options=barrier_options)

        adaptive = (adaptive_restart and warm_start_options is None
                    and transcription_for(model, options, grid,
                                          compiled=compiled).restarts(warm_start))
        if adaptive:
            result = restart(WARM_START_STAGE, restart_options(options))
        if result is None or not result.success:
            result = restart(MONOTONE_RESTART_STAGE if adaptive else WARM_START_STAGE,
                             warm_start_options)
        if not result.success:
            result = None
        elif check_warm_start and options.mesh_tol is None:
            run.check(result, check_start)
    outcome: Result | None = result
    if result is None and continues_from_paper(options):
        outcome = run.other_cost()
        result = outcome if outcome is not None and outcome.success else None
    elif result is None:
        # A free speed starts from the reference speed moved into its bounds (a run's
        # --speed-bounds 150m/min,400m/min start at 150 m/min, by continuation if need be).
        lo, hi = options.speed_bounds
        speed = (options.speed if options.speed is not None
                 else min(max(run.reference_speed, lo), hi))
        far = options.continuation and abs(speed - run.reference_speed) > 1e-9
        if options.multistart:
            starts = run.cold_starts(speed, every_start=True)
            if far:
                continued = run.speed_continuation(speed)
                starts += [continued] if continued is not None else []
            outcome = run.best_completion(distinct(starts, run.scale.length(SAME_STEP)))
        else:
            coarse = run.cold(speed)
            if far and coarse is None:
                coarse = run.speed_continuation(speed)
            outcome = run.complete(coarse)
    if outcome is not None and outcome.success:
        outcome = run.refine_mesh(outcome)
    if not run.results:  # no stage ran: every naive start was beyond the legs' reach
        raise GaitOptionsError(unplaced_message(options, run.unplaced))
    final = outcome if outcome is not None and outcome.success else run.final()
    return StagedRun(model=model, options=options, result=final,
                     stages=tuple(run.stages), wall_time_s=time.perf_counter() - start,
                     grid_costs=tuple(run.grid_costs),
                     stage_results=tuple(run.named_results))


#: Two coarse optima are the same start for :func:`distinct` when their costs differ by less
#: than this (relative) and their step lengths by less than :data:`SAME_STEP` (m): IPOPT's
#: tolerance leaves differences of about 1e-7; the branches differ by 10-25 %.
SAME_COST = 1e-5
SAME_STEP = 1e-4


def distinct(results: list[Result], same_step: float = SAME_STEP) -> list[Result]:
    """``results`` without those that repeat an earlier one (:data:`SAME_COST`, and step
    lengths within ``same_step``, m: :data:`SAME_STEP` on the reference biped): starts that
    found the same optimum are completed once."""
    kept: list[Result] = []
    for r in results:
        if not any(abs(r.objective - k.objective) <= SAME_COST * abs(k.objective)
                   and abs(r.parameters.get(STEP_LENGTH, 0.0)
                           - k.parameters.get(STEP_LENGTH, 0.0))
                   <= same_step for k in kept):
            kept.append(r)
    return kept


def unplaced_message(options: GaitOptions, unplaced: list[tuple[float, float, str]]) -> str:
    """Why no naive start could be placed, and what to change. A start walks the hip at a
    constant height and speed; at the heel strike it is ``L (1 - f/2)`` ahead of the stance
    tip (step length ``L``, single-support fraction ``f``), which the stance leg must reach."""
    step, r_max, why = max(unplaced, key=lambda u: u[0]) if unplaced else (nan, nan, "")
    if r_max == 0.0:  # the generic guess (no thigh-shank legs): no closed-form reach
        return (f"targets.step_length = {step:.3g} m: every naive start puts a leg beyond its "
                f"reach ({why}): a shorter step or a lower speed")
    f = options.single_support_fraction
    longest = r_max / (1.0 - f / 2.0)
    return (f"targets.step_length = {step:.3g} m: every naive start puts a leg beyond its "
            f"reach ({why}); at single-support fraction {f:g} a step of this model's legs "
            f"(reach {r_max:.3g} m) is at most about {longest:.3g} m: a shorter step, a "
            "lower speed or a smaller single-support fraction")


__all__ = ["PRIMAL_WARM_OPTIONS", "REFERENCE_SPEED", "Grid", "ProgressFn", "StageRecord",
           "StagedRun", "solve_walking", "transcription_for", "warm_start_grid"]
