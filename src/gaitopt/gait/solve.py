"""Solving the walking problem robustly from a naive start: staged continuation.

The paper's authors climbed to the optimum by hand through sub-problems. gaitopt does it by
itself, in stages that each warm-start the next:

1. ``relaxed``: the coarse grid (at most the paper's 8 + 5 knots), the unilateral contact
   conditions relaxed (normal forces and impulses may be negative), from the geometric guess
   of :mod:`gaitopt.gait.guess` at the target speed;
2. ``enforced``: the same grid with the contact conditions enforced (the paper's two-stage
   process);
3. ``target grid``: the requested grid, if finer, from stage 2 interpolated onto it.

If stage 1 or 2 fails, the same is tried from other naive guesses (shorter and longer
steps), then by continuation in speed from the reference speed (12 m/min). Given a warm start
(a neighbouring gait), the target problem is solved from it directly and the cold path is the
fallback. Every stage is reported through ``progress`` and kept in the solution, so a failure
says which stage failed and why.

Transcriptions (NLP and IPOPT solver) are built once per process for each problem structure
and reused: speed, step length and impulse enter through parameter bounds only.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gaitopt.dynamics.reduced import checked_biped
from gaitopt.gait.guess import WalkingGuess, default_step_length, naive_guess
from gaitopt.gait.options import GaitOptions, validate_options
from gaitopt.gait.problem import Relaxation, parameter_bounds, walking_problem
from gaitopt.ocp import Guess, PhaseGuess, Result, Transcription, transcribe
from gaitopt.robot.model import RobotModel

#: Reference speed (m/s) for the continuation fallback: the paper's optimal 12 m/min.
REFERENCE_SPEED = 0.2
#: Relaxation of the first stage (N, N s): large enough to switch the conditions off.
RELAXED = Relaxation(force=1e4, impulse=1e3)
#: Largest speed change (m/s) between two continuation steps.
SPEED_STEP = 0.1

ProgressFn = Callable[["StageReport"], None]


@dataclass(frozen=True)
class StageReport:
    """What one stage did: its name, the grid, the outcome and the time it took."""

    name: str
    knots: tuple[int, int]
    status: str
    success: bool
    iterations: int
    objective: float
    violation: float
    wall_time_s: float
    parameters: dict[str, float]

    def line(self) -> str:
        p = self.parameters
        return (f"{self.name:<22} {self.knots[0]}+{self.knots[1]} knots  "
                f"{'ok ' if self.success else 'FAILED'} {self.status:<28} "
                f"it {self.iterations:>4}  J {self.objective:10.4g}  "
                f"v {p.get('speed', float('nan')) * 60:6.2f} m/min  "
                f"L {p.get('step_length', float('nan')):.4f} m  "
                f"viol {self.violation:.1e}  {self.wall_time_s:6.2f} s")


@dataclass(frozen=True)
class WalkingSolution:
    """The outcome of :func:`solve_walking`: the final OCP result and every stage."""

    model: RobotModel
    options: GaitOptions
    result: Result
    stages: tuple[StageReport, ...]
    wall_time_s: float
    transcription: Transcription = field(repr=False)

    @property
    def success(self) -> bool:
        return self.result.success

    @property
    def failed_stage(self) -> StageReport | None:
        """The last failed stage when the solve failed."""
        if self.success:
            return None
        failed = [s for s in self.stages if not s.success]
        return failed[-1] if failed else None


_CACHE: dict[tuple[Any, ...], Transcription] = {}


def _structure_key(model: RobotModel, options: GaitOptions, knots: tuple[int, int],
                   relax: Relaxation, compiled: str | None) -> tuple[Any, ...]:
    o = options
    return (model.content_hash(), o.ankle, o.single_support_fraction, tuple(knots),
            o.transcription, o.periodic_controls, o.friction, o.min_stance_knee_flexion,
            tuple(o.torso_bounds), o.rate_bound, o.max_impulse, o.tol, o.max_iter,
            tuple(o.speed_bounds), tuple(o.step_length_bounds), relax, compiled)


def transcription_for(model: RobotModel, options: GaitOptions, knots: tuple[int, int],
                      relax: Relaxation = Relaxation(), *, compiled: str | None = None
                      ) -> Transcription:
    """The (process-wide cached) transcription of the walking problem on ``knots``."""
    key = _structure_key(model, options, knots, relax, compiled)
    if key not in _CACHE:
        problem = walking_problem(model, options.replace(knots=tuple(knots)), relax)
        intervals = {problem.phases[i].name: knots[i] - 1 for i in range(len(problem.phases))}
        _CACHE[key] = transcribe(
            problem, method=options.transcription, intervals=intervals, compiled=compiled,
            options={"ipopt.tol": options.tol, "ipopt.max_iter": options.max_iter,
                     "ipopt.acceptable_tol": max(options.tol * 100, 1e-6),
                     "show_eval_warnings": False})
    return _CACHE[key]


def ocp_guess(guess: WalkingGuess) -> Guess:
    """The engine's guess object from a walking guess (values at normalised knot times)."""
    phases = {}
    for ph in guess.phases:
        span = ph.t[-1] - ph.t[0]
        phases[ph.name] = PhaseGuess(x=ph.x, u=ph.u, tau=(ph.t - ph.t[0]) / span)
    return Guess(phases=phases, parameters=dict(guess.parameters))


def coarse_knots(options: GaitOptions) -> tuple[int, int]:
    """The grid of the first stages: the requested one, at most the paper's 8 + 5."""
    return (min(8, options.knots[0]), min(5, options.knots[1]))


class _Run:
    """One call of :func:`solve_walking`: runs stages and records them."""

    def __init__(self, model: RobotModel, options: GaitOptions, progress: ProgressFn | None,
                 compiled: str | None) -> None:
        self.model, self.options, self.progress, self.compiled = model, options, progress, \
            compiled
        self.stages: list[StageReport] = []
        self.last: tuple[Result, Transcription] | None = None

    def stage(self, name: str, knots: tuple[int, int], relax: Relaxation,
              guess: Guess | Result, bounds: dict[str, Any]) -> Result:
        tr = transcription_for(self.model, self.options, knots, relax, compiled=self.compiled)
        start = time.perf_counter()
        result = tr.solve(guess, parameters=bounds)
        report = StageReport(
            name=name, knots=tuple(knots), status=result.status, success=result.success,
            iterations=result.iterations, objective=result.objective,
            violation=result.constraint_violation, wall_time_s=time.perf_counter() - start,
            parameters=dict(result.parameters))
        self.stages.append(report)
        self.last = (result, tr)
        if self.progress is not None:
            self.progress(report)
        return result

    def cold(self, speed: float, step_length: float | None) -> Result | None:
        """Stages 1-2 on the coarse grid at ``speed`` from naive guesses."""
        o, coarse = self.options, coarse_knots(self.options)
        legs = checked_biped(self.model).legs
        r_max = min(leg.reach(-o.min_stance_knee_flexion) for leg in legs)
        bounds = parameter_bounds(o)
        base = step_length if step_length is not None else default_step_length(speed)
        target_speed = bounds["speed"]
        for factor in (1.0, 0.7, 1.4):
            step0 = base if step_length is not None else base * factor
            if step_length is not None and factor != 1.0:
                break
            guess = naive_guess(self.model, speed=speed, step_length=step0,
                                single_support_fraction=o.single_support_fraction,
                                knots=coarse, ankle=o.ankle, r_max=r_max)
            stage_bounds = dict(bounds)
            stage_bounds["speed"] = (speed, speed) if o.speed is not None else target_speed
            relaxed = self.stage("relaxed contact", coarse, RELAXED, ocp_guess(guess),
                                 stage_bounds)
            if not relaxed.success:
                continue
            enforced = self.stage("enforced contact", coarse, Relaxation(), relaxed,
                                  stage_bounds)
            if enforced.success:
                return enforced
        return None

    def refine(self, result: Result) -> Result:
        """Stage 3: the requested grid, when finer than the coarse one."""
        o = self.options
        if tuple(o.knots) == coarse_knots(o):
            return result
        return self.stage("target grid", tuple(o.knots), Relaxation(), result,
                          parameter_bounds(o))

    def speed_continuation(self, target: float) -> Result | None:
        """Solve at the reference speed, then step toward ``target``."""
        o = self.options
        current = self.cold(REFERENCE_SPEED, o.step_length)
        if current is None:
            return None
        speeds = np.linspace(REFERENCE_SPEED, target,
                             int(np.ceil(abs(target - REFERENCE_SPEED) / SPEED_STEP)) + 1)[1:]
        bounds = parameter_bounds(o)
        for v in speeds:
            b = dict(bounds)
            b["speed"] = (float(v), float(v))
            current = self.stage(f"continuation {v * 60:.1f} m/min", coarse_knots(o),
                                 Relaxation(), current, b)
            if not current.success:
                return None
        return current


def solve_walking(model: RobotModel, options: GaitOptions, *,
                  warm_start: Guess | Result | None = None,
                  progress: ProgressFn | None = None,
                  compiled: str | None = None) -> WalkingSolution:
    """Solve the walking problem (see the module docstring). Never raises for a failed solve:
    the returned solution says whether it succeeded and which stage failed."""
    validate_options(options, checked_biped(model))
    start = time.perf_counter()
    run = _Run(model, options, progress, compiled)
    result: Result | None = None
    if warm_start is not None:
        result = run.stage("warm start", tuple(options.knots), Relaxation(), warm_start,
                           parameter_bounds(options))
        if not result.success:
            result = None
    if result is None:
        speed = options.speed if options.speed is not None else REFERENCE_SPEED
        coarse = run.cold(speed, options.step_length)
        if coarse is None and options.continuation and abs(speed - REFERENCE_SPEED) > 1e-9:
            coarse = run.speed_continuation(speed)
        if coarse is not None:
            result = run.refine(coarse)
    if result is None:
        assert run.last is not None
        result = run.last[0]
    assert run.last is not None
    tr = transcription_for(model, options, tuple(options.knots), Relaxation(),
                           compiled=compiled) if result.success else run.last[1]
    return WalkingSolution(model=model, options=options, result=result,
                           stages=tuple(run.stages), wall_time_s=time.perf_counter() - start,
                           transcription=tr)
