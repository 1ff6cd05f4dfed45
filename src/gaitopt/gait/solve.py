"""Solving the walking problem robustly from a naive start: staged continuation.

The paper's authors climbed to the optimum by hand through sub-problems. gaitopt does it by
itself, in stages that each warm-start the next (primal values and multipliers):

1. ``relaxed contact``: the coarse grid (at most the paper's 8 + 5 knots) at the target speed
   (12 m/min when the speed is free) with no liftoff impulse, the unilateral contact
   conditions relaxed (normal forces and impulses may be negative), from the geometric guess
   of :mod:`gaitopt.gait.guess`, with IPOPT's adaptive barrier update
   (:data:`COLD_START_OPTIONS`);
2. ``enforced contact``: the same with the contact conditions enforced (the paper's two-stage
   process);
3. ``liftoff impulse free`` (impulse variants) and ``speed free`` (the optimal walk): the
   parameters held fixed so far are released one at a time; starting from the no-impulse gait
   keeps the impulse variants from stopping in worse local minima than the no-impulse gait;
4. ``target grid``: the requested grid, if finer, from the coarse solution interpolated
   (started with a small barrier, :data:`PRIMAL_WARM_OPTIONS`, and solved with a
   limited-memory Hessian, :data:`FINE_STAGE_OPTIONS`);
5. ``mesh refinement N`` (with ``mesh_tol``): every interval whose collocation error estimate
   exceeds ``mesh_tol`` is split (:func:`gaitopt.ocp.refined_mesh`) and the problem solved
   again from the last solution, until every estimate is within ``mesh_tol``; then ``mesh
   check (halved)``: every interval halved, for the cost error estimate. The rounds work on
   the :class:`~gaitopt.ocp.Transcription` and :class:`~gaitopt.ocp.Result` only.

If stage 1 or 2 fails, the same is tried from guesses with shorter and longer steps, then by
continuation in speed from the reference speed (12 m/min). With ``multistart`` all three
guesses and (away from 12 m/min) the continuation in speed are solved and the lowest
coarse optimum is kept: the problem has several local optima (a long-step and a short-step
branch at high speed), and a single cold start can end on the worse one. Given a warm start
(a neighbouring gait), the target problem is solved from it directly and the cold path is the
fallback.
Every stage is reported through ``progress`` and kept in the solution, so a failure says which
stage failed and why.

Transcriptions (NLP and IPOPT solver) are built once per process for each problem structure
and reused: speed, step length and impulse enter through parameter bounds only.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import pickle
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from gaitopt import codegen
from gaitopt.fileio import write_bytes_atomic
from gaitopt.gait.formulation import (
    biped_of,
    checked_sequence,
    contact_sequence,
    problem_for,
    stage_bounds,
)
from gaitopt.gait.full_physics import model_symmetry
from gaitopt.gait.guess import (
    WalkingGuess,
    default_running_step,
    default_step_length,
    naive_guess,
    naive_running_guess,
)
from gaitopt.gait.options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.problem import FRACTION, Relaxation, parameter_bounds, with_step_time
from gaitopt.gait.sequence_guess import sequence_guess
from gaitopt.ocp import (
    Bounds,
    Guess,
    PhaseGuess,
    Result,
    Transcription,
    WarmStart,
    refined_mesh,
    transcribe,
)
from gaitopt.ocp.mesh import split_intervals
from gaitopt.robot.model import RobotModel

#: Reference speed (m/s) for the continuation fallback: the paper's optimal 12 m/min.
REFERENCE_SPEED = 0.2
#: Relaxation of the first stage (N, N s): large enough to switch the conditions off.
RELAXED = Relaxation(force=1e4, impulse=1e3)
#: Largest speed change (m/s) between two continuation steps.
SPEED_STEP = 0.1
#: Largest constraint violation (in the constraints' own units) of a solution that IPOPT
#: accepted at its "acceptable" level for it to count as converged: the tolerance to which
#: verify checks what the transcription imposes exactly.
ACCEPTABLE_VIOLATION = 1e-6
#: Smoothing (W) of the positive parts of the work costs in the first stage after the paper
#: cost's optimum, when the requested one is finer.
COST_SMOOTHING_START = 1.0
#: IPOPT options of the first stage, solved from the naive guess. IPOPT's adaptive barrier
#: update (Nocedal, Waechter and Waltz) needs fewer iterations from a poor start and finds
#: the lower local optimum more often than the default monotone one: over 20 speeds with and
#: without ankle torques (IPOPT 3.14.19 with MUMPS 5.8.2, as CasADi 3.8 bundles it) the
#: monotone update took up to 522 iterations and stopped in worse optima at 6-12 m/min, and
#: failed at 3 m/min with ankle torques. The later stages start from a solution and keep the
#: monotone update with a small initial barrier (see :meth:`gaitopt.ocp.Transcription.solve`).
COLD_START_OPTIONS = {"ipopt.mu_strategy": "adaptive"}
#: IPOPT options of a stage started from the values of a solution without its multipliers
#: (a coarse solution interpolated onto the target grid, a neighbouring gait): the start is
#: close to the optimum, so a small initial barrier and a small push off the bounds keep it
#: there instead of moving it to the interior first. At 40 + 10 knots this took the target
#: grid stage from 102 to 33 iterations. (With the multipliers, the transcription's own
#: warm-start options apply instead.)
PRIMAL_WARM_OPTIONS = {"ipopt.mu_init": 1e-4, "ipopt.bound_push": 1e-6,
                       "ipopt.bound_frac": 1e-6}
#: The Hessian of the target-grid stages of a cold solve: a limited-memory quasi-Newton
#: approximation (as SNOPT's, which the paper used). Deriving the exact Hessian of the
#: expanded NLP costs far more than these stages: at 40 + 10 knots 9-12 s against 2 s for
#: the functions without it, while the two stages took 78 + 27 quasi-Newton iterations (about
#: 2 s) to the same optimum and tolerance. Warm starts on a fine grid (a sweep's neighbours)
#: use the exact Hessian, built once per process.
FINE_STAGE_OPTIONS = {"ipopt.hessian_approximation": "limited-memory"}


def fine_stage_options(options: GaitOptions) -> dict[str, Any]:
    """:data:`FINE_STAGE_OPTIONS` in the reduced formulation; the exact Hessian in the full
    one, where the quasi-Newton stages took 365 + 228 iterations at 16 + 6 knots and ended
    at IPOPT's acceptable level, against 23 + 13 with the exact Hessian (12 m/min), and
    with point-assembled derivatives (:func:`evaluation_mode`), whose exact Hessian costs
    no derivation of the whole NLP."""
    if options.formulation != "reduced" or evaluation_mode(options, None) == "points":
        return {}
    return dict(FINE_STAGE_OPTIONS)


#: Most refinement rounds after the fixed-grid stages, and most knots per phase they may make
#: (the bound of ``GaitOptions.knots``).
MAX_REFINEMENTS = 6
MAX_REFINED_KNOTS = 400

ProgressFn = Callable[["StageReport"], None]
#: A grid: knots per phase (single support, double support), uniform, or one array of
#: normalised knot times in [0, 1] per phase of the problem (a refined mesh).
Grid = tuple[int, int] | tuple[np.ndarray, ...]


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
    #: Solves the target problem itself (no relaxation, nothing held): its objective is
    #: comparable between grids (the cost error estimate uses it).
    full_problem: bool = False

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
    stage_results: tuple[tuple[str, Result], ...] = ()
    """Every stage's name and result, in order (for diagnosing a failure)."""
    #: The full-problem stages that converged, (knots per phase, cost), in order: the grids
    #: the cost was computed on (the cost error estimate compares the last two).
    grid_costs: tuple[tuple[tuple[int, ...], float], ...] = ()

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


def is_mesh(grid: Grid) -> bool:
    """Whether ``grid`` is a mesh (arrays of normalised knots) rather than knot counts."""
    return not all(isinstance(k, int | np.integer) for k in grid)


def grid_knots(grid: Grid, options: GaitOptions) -> tuple[int, int]:
    """Knots per phase of a grid (a phase the problem lacks keeps ``options.knots``)."""
    if not is_mesh(grid):
        return (int(grid[0]), int(grid[1]))
    sizes = [np.asarray(m).size for m in grid]
    return (sizes[0], sizes[1] if len(sizes) > 1 else options.knots[1])


def _grid_key(grid: Grid) -> tuple[Any, ...]:
    if not is_mesh(grid):
        return tuple(int(k) for k in grid)
    return tuple(tuple(float(v) for v in np.asarray(m)) for m in grid)


#: Options that enter a solve only through bounds or the solve's own logic, never the NLP's
#: structure: problems that differ only in these share one transcription.
BOUNDS_ONLY_OPTIONS = frozenset({"speed", "step_length", "step_time", "knots", "multistart",
                                 "continuation", "mesh_tol"})


def _structure_key(model: RobotModel, options: GaitOptions, grid: Grid,
                   compiled: str | None) -> tuple[Any, ...]:
    """Every option that shapes the NLP (all but :data:`BOUNDS_ONLY_OPTIONS`), the model,
    the grid, whether a step-time row exists, and the compilation mode."""
    shaping = sorted((k, repr(v)) for k, v in dataclasses.asdict(options).items()
                     if k not in BOUNDS_ONLY_OPTIONS)
    return (model.content_hash(), _grid_key(grid), options.step_time is not None, compiled,
            tuple(shaping))


def evaluation_mode(options: GaitOptions, compiled: str | None) -> str | None:
    """How the NLP of ``options`` is evaluated (``transcribe(..., compiled=...)``): the
    separated Hermite-Simpson form always by ``"points"``, its derivatives assembled from
    compiled functions of one grid point (:mod:`gaitopt.ocp.pointwise`: compiled once per
    model and problem structure into the disk cache, CasADi's VM without a C compiler;
    several times faster per iteration than the alternatives); other transcriptions as
    ``compiled`` asks (``None``: CasADi's VM on the expanded NLP)."""
    if options.transcription == "hermite-simpson-separated":
        return "points"
    if compiled == "codegen":
        raise GaitOptionsError(
            f"compiled: the {options.transcription!r} NLP generated as one C file does not "
            "compile in minutes (34 MB of C at 8 + 5 knots); use transcription "
            "'hermite-simpson-separated', whose derivatives are always compiled per grid "
            "point")
    return compiled


#: Version of the disk cache of the walking problem's symbolic functions (part of its key).
FUNCTIONS_FORMAT = "gaitopt-walking-functions-1"


@functools.cache
def source_hash() -> str:
    """A hash of every Python file of the installed gaitopt package: the symbolic functions
    cached on disk are those this code builds."""
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:20]


def functions_file(key: tuple[Any, ...]) -> Path:
    """Where the symbolic functions (``Transcription.functions``) of the problem of the
    structure ``key`` (:func:`_structure_key`) are cached on disk: keyed by the model, every
    shaping option, the gaitopt sources and CasADi's version, not the grid or the mode."""
    text = repr((FUNCTIONS_FORMAT, source_hash(), ca.CasadiMeta.version(), key[0], key[2],
                 key[4]))
    name = hashlib.sha256(text.encode()).hexdigest()[:24]
    return codegen.cache_dir() / f"walking-functions-{name}.pickle"


def cached_functions(path: Path) -> Any:
    """The functions pickled at ``path``, or None (missing, unreadable or stale: rebuilt)."""
    try:
        return pickle.loads(path.read_bytes())
    except Exception:  # noqa: BLE001 - any unreadable cache file is rebuilt and replaced
        return None


def transcription_for(model: RobotModel, options: GaitOptions, knots: Grid, *,
                      compiled: str | None = None) -> Transcription:
    """The (process-wide cached) transcription of the walking problem on ``knots`` (knot
    counts per phase, or a mesh: normalised knot times per phase). Its symbolic functions
    (independent of the grid) come from another grid's transcription in this process, or
    from the disk cache (:func:`functions_file`), or are built and saved there."""
    compiled = evaluation_mode(options, compiled)
    key = _structure_key(model, options, knots, compiled)
    if key not in _CACHE:
        same = [tr.functions for k, tr in _CACHE.items() if k[0] == key[0] and k[2:] == key[2:]]
        path = functions_file(key)
        functions = same[0] if same else cached_functions(path)
        counts = grid_knots(knots, options)
        problem = problem_for(model, options.replace(knots=counts))
        intervals: dict[str, Any] = {
            ph.name: (np.asarray(knots[i], dtype=float) if is_mesh(knots)
                      else counts[min(i, len(counts) - 1)] - 1)
            for i, ph in enumerate(problem.phases)}
        _CACHE[key] = transcribe(
            problem, method=options.transcription, intervals=intervals, compiled=compiled,
            options={"ipopt.tol": options.tol, "ipopt.max_iter": options.max_iter,
                     "ipopt.acceptable_tol": max(options.tol * 100, 1e-6),
                     "show_eval_warnings": False},
            build_solver=False, functions=functions)
        if functions is None:
            with contextlib.suppress(OSError):  # a read-only cache: build again next time
                write_bytes_atomic(path, pickle.dumps(_CACHE[key].functions))
    return _CACHE[key]


def held_ankles(model: RobotModel, tr: Transcription, bounds: Bounds) -> Bounds:
    """``bounds`` with every ankle torque of every phase bounded to zero."""
    ankles = {a.name for a in model.actuators if a.contact is not None}
    for ph in tr.problem.phases:
        for name in ph.controls:
            if name in ankles:
                bounds = bounds.with_control(ph.name, name, 0.0, 0.0)
    return bounds


def ocp_guess(guess: WalkingGuess) -> Guess:
    """The engine's guess object from a walking guess (values at normalised knot times)."""
    phases = {}
    for ph in guess.phases:
        span = ph.t[-1] - ph.t[0]
        phases[ph.name] = PhaseGuess(
            x={n: ph.x[:, j] for j, n in enumerate(ph.states)},
            u={n: ph.u[:, j] for j, n in enumerate(ph.controls)}, tau=(ph.t - ph.t[0]) / span)
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
        self.results: list[Result] = []
        self.named_results: list[tuple[str, Result]] = []
        self.grid_costs: list[tuple[tuple[int, ...], float]] = []

    def stage(self, name: str, knots: Grid, relax: Relaxation,
              guess: Guess | Result | WarmStart, bounds: dict[str, Any], *,
              hold_ankles: bool = False, solver_options: dict[str, Any] | None = None,
              problem: GaitOptions | None = None) -> Result:
        """Solve one stage; a Result guess also passes its multipliers to IPOPT.
        ``hold_ankles`` bounds the ankle torques to zero (the no-ankle gait);
        ``solver_options`` are merged over the transcription's; ``problem`` replaces the
        run's options for this stage's NLP (another cost, say)."""
        tr = transcription_for(self.model, problem or self.options, knots,
                               compiled=self.compiled)
        start = time.perf_counter()
        nlp_bounds = with_step_time(stage_bounds(tr, relax, self.options), self.options)
        if hold_ankles:
            nlp_bounds = held_ankles(self.model, tr, nlp_bounds)
        result = tr.solve(guess, bounds=nlp_bounds, parameters=bounds, options=solver_options,
                          warm_start_multipliers=isinstance(guess, Result | WarmStart))
        result = converged_or_failed(result)
        full = (relax == Relaxation() and not hold_ankles
                and dict(bounds) == dict(parameter_bounds(self.options)))
        report = StageReport(
            name=name, knots=grid_knots(knots, self.options), status=result.status,
            success=result.success, iterations=result.iterations, objective=result.objective,
            violation=result.constraint_violation, wall_time_s=time.perf_counter() - start,
            parameters=dict(result.parameters), full_problem=full)
        self.stages.append(report)
        self.results.append(result)
        self.named_results.append((name, result))
        if full and result.success:
            self.grid_costs.append((tuple(m.size for m in result.mesh), result.objective))
        if self.progress is not None:
            self.progress(report)
        return result

    def cold(self, speed: float, *, every_start: bool = False) -> Result | None:
        """Stages 1-2 on the coarse grid at ``speed`` without impulse, from naive guesses
        (the requested step length, or a speed-based guess and two others): the first that
        converges, or with ``every_start`` the best of all that converge."""
        o, coarse = self.options, coarse_knots(self.options)
        biped = biped_of(self.model, o)
        generic = biped is None or o.gait == "heel-toe" or o.contact_sequence is not None
        r_max = (0.0 if biped is None else
                 min(leg.reach(-o.min_stance_knee_flexion) for leg in biped.legs))
        bounds = held_fraction(dict(parameter_bounds(o)), o)
        bounds["speed"] = (speed, speed)
        bounds["impulse"] = (0.0, 0.0)
        if o.step_length is not None:
            steps = [o.step_length]
        elif o.step_time is not None:
            steps = [o.step_time * speed]
        else:
            default = default_running_step if o.gait == "run" else default_step_length
            steps = [default(speed) * f for f in (1.0, 0.7, 1.4)]
        found: list[Result] = []
        for step0 in steps:
            if generic:
                guess = sequence_guess(self.model, contact_sequence(self.model, o),
                                       model_symmetry(self.model).contacts, speed=speed,
                                       step_length=step0, knots=coarse, ankle=o.ankle,
                                       ankle_torques=False)
            elif o.gait == "run":
                guess = naive_running_guess(
                    self.model, speed=speed, step_length=step0,
                    stance_fraction=o.single_support_fraction, knots=coarse, ankle=o.ankle,
                    r_max=r_max, ankle_torques=False)
            else:
                guess = naive_guess(self.model, speed=speed, step_length=step0,
                                    single_support_fraction=o.single_support_fraction,
                                    knots=coarse, ankle=o.ankle, r_max=r_max,
                                    ankle_torques=False, full=o.formulation == "full")
            start = ocp_guess(guess)
            if FRACTION in bounds:  # a free fraction starts at its guess
                start = Guess(phases=start.phases, parameters={
                    **start.parameters, FRACTION: o.single_support_fraction})
            relaxed = self.stage("relaxed contact", coarse, RELAXED, start, bounds,
                                 hold_ankles=o.ankle, solver_options=COLD_START_OPTIONS)
            if not relaxed.success:
                continue
            enforced = self.stage("enforced contact", coarse, Relaxation(), relaxed, bounds,
                                  hold_ankles=o.ankle)
            if enforced.success:
                if not every_start:
                    return enforced
                found.append(enforced)
        return best_of(found)

    def release(self, result: Result) -> Result:
        """Free what the cold stages held fixed: the ankle torques, the impulse, the speed."""
        o, coarse = self.options, coarse_knots(self.options)
        bounds = held_fraction(dict(parameter_bounds(o)), o, result)
        speed = result.parameters["speed"]
        if o.ankle:
            b = dict(bounds)
            b["speed"] = (speed, speed)
            b["impulse"] = (0.0, 0.0)
            result = self.stage("ankle torques free", coarse, Relaxation(), result, b)
            if not result.success:
                return result
        if o.impulse and o.double_support:
            b = dict(bounds)
            b["speed"] = (speed, speed)
            result = self.stage("liftoff impulse free", coarse, Relaxation(), result, b)
            if not result.success:
                return result
        if FRACTION in bounds:
            b = dict(parameter_bounds(o))
            b["speed"] = (speed, speed)
            result = self.stage("single-support fraction free", coarse, Relaxation(), result,
                                b)
            if not result.success:
                return result
        if o.speed is None:
            result = self.stage("speed free", coarse, Relaxation(), result, parameter_bounds(o))
        return result

    def refine(self, result: Result) -> Result:
        """The requested grid, when finer than the coarse one: first with the step length and
        speed held at the coarse solution's (a fine grid started from a coarse solution with
        them free can wander to a far worse local optimum), then released."""
        o = self.options
        if tuple(o.knots) == coarse_knots(o):
            return result
        return self.on_grid("target grid", o.knots, result)

    def on_grid(self, name: str, grid: Grid, result: Result) -> Result:
        """Solve on ``grid`` from ``result`` (another grid): the step length and speed held
        at ``result``'s, then (stage ``name, all free``) released."""
        o = self.options
        held = dict(parameter_bounds(o))
        for key in ("step_length", "speed"):
            held[key] = (result.parameters[key], result.parameters[key])
        fine = self.stage(name, grid, Relaxation(), result, held,
                          solver_options={**PRIMAL_WARM_OPTIONS, **fine_stage_options(o)})
        all_fixed = o.speed is not None and (o.step_length is not None or
                                             o.step_time is not None)
        if not fine.success or all_fixed:
            return fine
        return self.stage(f"{name}, all free", grid, Relaxation(), fine,
                          parameter_bounds(o), solver_options=fine_stage_options(o))

    def refine_mesh(self, result: Result) -> Result:
        """Refinement rounds (``mesh_tol``): split the intervals whose error estimate exceeds
        the tolerance and solve again from ``result`` until every estimate is within it (at
        most :data:`MAX_REFINEMENTS` rounds and :data:`MAX_REFINED_KNOTS` knots per phase);
        then one round on that mesh with every interval halved, whose solution is the
        answer and whose cost change from the mesh before is the cost error estimate
        (:mod:`gaitopt.gait.accuracy`). Successive adaptive meshes differ by a few knots
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
            result = self.on_grid(f"mesh refinement {round_}", mesh, result)
            if not result.success:
                return result
        halved = tuple(split_intervals(m, np.full(m.size - 1, 2, dtype=np.int64))
                       for m in result.mesh)
        if max(m.size for m in halved) > MAX_REFINED_KNOTS:
            return result
        return self.on_grid("mesh check (halved)", halved, result)

    def speed_continuation(self, target: float) -> Result | None:
        """Solve at the reference speed, then step toward ``target``."""
        o = self.options
        current = self.cold(REFERENCE_SPEED)
        if current is None:
            return None
        speeds = np.linspace(REFERENCE_SPEED, target,
                             int(np.ceil(abs(target - REFERENCE_SPEED) / SPEED_STEP)) + 1)[1:]
        bounds = held_fraction(dict(parameter_bounds(o)), o)
        bounds["impulse"] = (0.0, 0.0)
        for v in speeds:
            b = dict(bounds)
            b["speed"] = (float(v), float(v))
            current = self.stage(f"continuation {v * 60:.1f} m/min", coarse_knots(o),
                                 Relaxation(), current, b, hold_ankles=o.ankle)
            if not current.success:
                return None
        return current

    def other_cost(self) -> Result | None:
        """A cost other than the paper's, by continuation: the whole solve with the paper's
        cost first (its stages reported with the prefix ``paper cost:``), then the cost
        asked for from that optimum, first with a coarse smoothing of the positive parts
        (:data:`COST_SMOOTHING_START`) when it is finer. None if the paper solve fails."""
        o = self.options
        paper = o.replace(cost="paper", cost_regularization=0.0)

        def report(stage: StageReport) -> None:
            stage = dataclasses.replace(stage, name=f"paper cost: {stage.name}")
            self.stages.append(stage)
            if self.progress is not None:
                self.progress(stage)

        start = solve_walking(self.model, paper, progress=report, compiled=self.compiled)
        if not start.success:
            self.results.append(start.result)
            return None
        guess: Guess | Result = result_guess(start.result)
        if o.cost != "paper" and o.cost_smoothing < COST_SMOOTHING_START:
            smooth = o.replace(cost_smoothing=COST_SMOOTHING_START)
            guess = self.stage(f"{o.cost} cost, eps {COST_SMOOTHING_START:g} W", o.knots,
                               Relaxation(), guess, parameter_bounds(o),
                               solver_options=PRIMAL_WARM_OPTIONS, problem=smooth)
            if not guess.success:
                return guess
            guess = result_guess(guess)
        return self.stage(f"{o.cost} cost", o.knots, Relaxation(), guess, parameter_bounds(o),
                          solver_options=PRIMAL_WARM_OPTIONS)

    def final(self) -> Result:
        """The last stage's outcome, or, if its values are not finite (a diverged solve),
        the last stage whose values are, marked failed."""
        for result in reversed(self.results):
            if np.all(np.isfinite(result.w)):
                if result is not self.results[-1]:
                    return _as_failed(result, self.results[-1])
                return result
        return self.results[-1]


def held_fraction(bounds: dict[str, Any], options: GaitOptions,
                  result: Result | None = None) -> dict[str, Any]:
    """``bounds`` with a free single-support fraction held (at ``result``'s value, or at its
    first guess ``options.single_support_fraction``); unchanged if it is not free."""
    if FRACTION in bounds:
        value = (result.parameters[FRACTION] if result is not None
                 else options.single_support_fraction)
        bounds[FRACTION] = (value, value)
    return bounds


def converged_or_failed(result: Result) -> Result:
    """``result``, marked failed if IPOPT stopped at its acceptable level (which CasADi reports
    as success) with a constraint violation above :data:`ACCEPTABLE_VIOLATION`: such a point
    does not meet the requested tolerances. A feasible acceptable-level point stays a success
    and keeps its status ``Solved_To_Acceptable_Level``, which the gait file records."""
    if (result.success and result.status == "Solved_To_Acceptable_Level"
            and result.constraint_violation > ACCEPTABLE_VIOLATION):
        return dataclasses.replace(
            result, success=False,
            message=f"IPOPT stopped at its acceptable level with a constraint violation of "
                    f"{result.constraint_violation:.2g} (more than {ACCEPTABLE_VIOLATION:g})")
    return result


def result_guess(result: Result) -> Guess:
    """A result's knot values and parameters as a guess (values only, no multipliers)."""
    phases = {ph.name: PhaseGuess(x=ph.x, u=ph.u, tau=(ph.t - ph.t[0]) / (ph.t[-1] - ph.t[0]))
              for ph in result.phases}
    return Guess(phases=phases, parameters=dict(result.parameters))


def best_of(results: Sequence[Result | None]) -> Result | None:
    """The converged result with the lowest objective (None if none converged)."""
    ok = [r for r in results if r is not None and r.success]
    return min(ok, key=lambda r: r.objective) if ok else None


def _as_failed(result: Result, failed: Result) -> Result:
    """``result``'s values with the failed stage's status (never reported as converged)."""
    return dataclasses.replace(result, success=False, status=failed.status,
                               message=f"{failed.message} (values of an earlier stage)")


def solve_walking(model: RobotModel, options: GaitOptions, *,
                  warm_start: Guess | Result | WarmStart | None = None,
                  progress: ProgressFn | None = None,
                  compiled: str | None = None) -> WalkingSolution:
    """Solve the walking problem (see the module docstring). Never raises for a failed solve:
    the returned solution says whether it succeeded and which stage failed."""
    validate_options(options, biped_of(model, options))
    checked_sequence(model, options)
    evaluation_mode(options, compiled)  # refuses a compilation that would take too long
    start = time.perf_counter()
    run = _Run(model, options, progress, compiled)
    result: Result | None = None
    if warm_start is not None:
        result = run.stage("warm start", warm_start_grid(options, warm_start), Relaxation(),
                           warm_start, parameter_bounds(options),
                           solver_options=PRIMAL_WARM_OPTIONS)
        if not result.success:
            result = None
    outcome: Result | None = result
    if result is None and (options.cost != "paper" or options.cost_regularization > 0.0):
        outcome = run.other_cost()
        result = outcome if outcome is not None and outcome.success else None
    elif result is None:
        speed = options.speed if options.speed is not None else REFERENCE_SPEED
        coarse = run.cold(speed, every_start=options.multistart)
        far = options.continuation and abs(speed - REFERENCE_SPEED) > 1e-9
        if far and (coarse is None or options.multistart):
            coarse = best_of([coarse, run.speed_continuation(speed)])
        if coarse is not None:
            outcome = run.release(coarse)
            if outcome.success:
                outcome = run.refine(outcome)
    if outcome is not None and outcome.success:
        outcome = run.refine_mesh(outcome)
    final = outcome if outcome is not None and outcome.success else run.final()
    return WalkingSolution(model=model, options=options, result=final,
                           stages=tuple(run.stages), wall_time_s=time.perf_counter() - start,
                           grid_costs=tuple(run.grid_costs),
                           stage_results=tuple(run.named_results))


def warm_start_grid(options: GaitOptions, warm_start: Guess | Result | WarmStart) -> Grid:
    """The grid of a warm start: ``options.knots``; with ``mesh_tol``, the warm start's own
    mesh (a refined gait's non-uniform knots), every other knot of it when each phase has an
    odd number >= 5: the mesh before the halving that ended its refinement, so that a chain
    of warm starts (a sweep) does not double the grid at every point."""
    if options.mesh_tol is None or isinstance(warm_start, WarmStart):
        return options.knots
    if isinstance(warm_start, Result):
        taus = [np.asarray(m, dtype=float) for m in warm_start.mesh]
    else:
        taus = [np.asarray(g.tau, dtype=float) for g in warm_start.phases.values()
                if g.tau is not None]
    phases = 2 if options.double_support else 1
    if len(taus) != phases or any(t.size < 2 for t in taus):
        return options.knots
    if all(t.size % 2 == 1 and t.size >= 5 for t in taus):
        taus = [t[::2] for t in taus]
    return tuple(taus)
