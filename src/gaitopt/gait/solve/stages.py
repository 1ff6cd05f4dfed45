"""The continuation stages of the staged solve, described as data, and what each one holds.

:data:`CONTACT_STAGES` run on the coarse grid (:func:`coarse_knots`) from each naive guess
in :data:`COLD_CONTROL_MODEL` with everything that :data:`RELEASES` frees held
(:func:`held_bounds`, :func:`held_ankles`); then each stage of :data:`COARSE_COMPLETION`
that runs for the options: :data:`CONTROL_MODEL_STAGE` (the requested control model) and the
:data:`RELEASES`, each freeing one quantity and holding what the later ones free.
:func:`gaitopt.gait.solve.staged.solve_walking` walks these lists; the IPOPT options of the stages
(and why) are here too.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from gaitopt.gait.formulations.select import formulation_of
from gaitopt.gait.formulations.step_parameters import (
    FRACTION,
    IMPULSE,
    SPEED,
    Relaxation,
    parameter_bounds,
)
from gaitopt.gait.options.gait_options import ControlModel, GaitOptions
from gaitopt.gait.sequence.contact_sequence import sequence_from_dict
from gaitopt.gait.sequence.phase_fractions import free_phases
from gaitopt.ocp import Bounds, Result, Transcription
from gaitopt.robot.model import RobotModel

#: Relaxation of the first stage (N, N s) on the reference biped (42 kg, 1 m legs; carried
#: over as a force and an impulse to another model): large enough to switch the conditions
#: off.
RELAXED = Relaxation(force=1e4, impulse=1e3)
#: IPOPT options of the first stage, solved from the naive guess. IPOPT's adaptive barrier
#: update (Nocedal, Waechter and Waltz) needs fewer iterations from a poor start and finds
#: the lower local optimum more often than the default monotone one: over 20 speeds with and
#: without ankle torques (IPOPT 3.14.19 with MUMPS 5.8.2, as CasADi 3.8 bundles it) the
#: monotone update took up to 522 iterations and stopped in worse optima at 6-12 m/min, and
#: failed at 3 m/min with ankle torques. The later stages start from a solution and keep the
#: monotone update with a small initial barrier (see :meth:`gaitopt.ocp.Transcription.solve`).
COLD_START_OPTIONS = {"ipopt.mu_strategy": "adaptive"}
#: IPOPT options of the second stage, started from the relaxed stage's solution and its
#: multipliers, which violates the enforced contact conditions by far: a larger initial
#: barrier than a warm start's (1e-4 instead of
#: :data:`gaitopt.ocp.transcription.WARM_START_OPTIONS`' 1e-6). At 8 + 5 knots, 3-60 m/min
#: (six speeds, both formulations) the stage took 160 instead of 311 iterations in full
#: coordinates and 212 instead of 264 in reduced ones, to the same optima (the final costs
#: equal to 8 digits). Used in full coordinates only: in reduced ones an infeasible request
#: (80 m/min with 0.75 m steps) then ended in a restoration failure at a far worse point
#: (contact forces violated by 611 N) instead of IPOPT's infeasibility verdict with every
#: torque at its bound, and the failure's diagnosis named the wrong cause.
ENFORCED_CONTACT_OPTIONS = {"ipopt.mu_init": 1e-4}
#: IPOPT options of a stage started from the values of a solution without its multipliers
#: (a coarse solution interpolated onto the target grid, a neighbouring gait): the start is
#: close to the optimum, so a small initial barrier and a small push off the bounds keep it
#: there instead of moving it to the interior first. At 40 + 10 knots this took the target
#: grid stage from 102 to 33 iterations. (With the multipliers, the transcription's own
#: warm-start options apply instead.)
PRIMAL_WARM_OPTIONS = {"ipopt.mu_init": 1e-4, "ipopt.bound_push": 1e-6,
                       "ipopt.bound_frac": 1e-6}
#: The stage that starts from a given solution or gait file (:func:`~gaitopt.gait.solve.staged.
#: solve_walking`'s ``warm_start``).
WARM_START_STAGE = "warm start"
#: The same start solved again with the monotone barrier, where the adaptive barrier's
#: restart (:data:`RESTART_OPTIONS`) did not converge.
MONOTONE_RESTART_STAGE = "warm start, monotone barrier"
#: At most this many IPOPT iterations for stage ``check grid``
#: (:data:`~gaitopt.gait.solve.staged_run.CHECK_GRID_STAGE`) when it starts
#: from the target grid's solution mapped with its multipliers
#: (:data:`~gaitopt.gait.solve.staged.REGRID_MOVES`: the heel-toe walk) and no stage of a
#: smoothing ladder or with the step held comes first. That start is usually the faster one
#: (the check grids of the feet cost study's accuracy passes: median 20 iterations, at most
#: 142 on the paper cost) but can run away: the paper cost's pass on 54 + 39 knots ran for
#: more than 15 minutes with the dual infeasibility at 1e3-1e9, where the values-only start
#: took 143 iterations (docs/results/benchmarks-gait.md, "Point libraries in chunks"). Such a
#: start is then solved again from the values only
#: (:data:`~gaitopt.gait.solve.staged_run.CHECK_FROM_VALUES_STAGE`).
CHECK_REGRID_MAX_ITER = 300
#: At most this many IPOPT iterations for stage :data:`WARM_START_STAGE` with
#: :data:`RESTART_OPTIONS`; a restart that has not converged by then is solved again from
#: the same start with the monotone barrier (stage :data:`MONOTONE_RESTART_STAGE`). The
#: adaptive restarts of the seven-link study's points from a neighbour's Result took 5-68
#: iterations, those of the seven-link and five-link walks from their 60 m/min files at
#: 0.8-1.2 times the speed 8-33 (docs/results/benchmarks-gait.md, "The warm start's
#: adaptive barrier"); at 1.5 times the seven-link's did not converge within the bound
#: (4.9 s lost; the monotone restart then took 36 iterations). The bound caps what a
#: restart that wanders costs.
RESTART_MAX_ITER = 100
#: IPOPT options of stage :data:`WARM_START_STAGE` when it restarts from a solution of the
#: same NLP on the same grid with its multipliers (a gait file's point, a sweep's
#: neighbour): merged over the transcription's warm-start options (barrier 1e-6, tiny
#: pushes off the bounds). IPOPT's adaptive barrier update (Nocedal, Waechter and Waltz,
#: with its quality-function oracle) leaves the 1e-6 barrier as soon as the start allows,
#: where the monotone update first solves the 1e-6 barrier problem (11 of its 17 iterations
#: at +5 % speed on the seven-link). Measured (docs/results/benchmarks-gait.md, "The warm
#: start's adaptive barrier"): ``bench/warm_restart.py``, the seven-link heel-toe walk
#: restarted from its 60 m/min optimum at 0.8-1.2 times the speed, 8-22 iterations instead
#: of 16-23 (at +5 %: 8 instead of 17, 0.38 instead of 0.68 s), the five-link walk 11-33
#: instead of 15-146, to the same optima (costs 2-4e-7 lower); ``gaitopt study --model
#: seven-link``, the 23 points started from a neighbour's Result, 337 instead of 507
#: iterations. Far from the file it can cost more (:data:`RESTART_MAX_ITER`). Only for a
#: start that solved the same problem (at another speed): a neighbour's Result in a sweep
#: (:data:`gaitopt.study.worker.ADAPTIVE_STARTS`), a gait file of the problem
#: (:func:`gaitopt.gait.api.solve_staged_run`); not for a secant prediction, a start mapped
#: from another grid or the file of another cost. MUMPS's default scalings are kept and
#: IPOPT checks its steps: with the scalings off or ``fast_step_computation`` an iteration
#: was a fifth cheaper at +5 % speed, but on a hard start (the study's 36 m/min point
#: without ankle torques, from the secant) the adaptive restart then did not converge in
#: 100 iterations, and without MUMPS's scaling each iteration took more than a second.
RESTART_OPTIONS: dict[str, Any] = {"ipopt.mu_strategy": "adaptive"}


def restart_options(options: GaitOptions) -> dict[str, Any]:
    """:data:`RESTART_OPTIONS` with at most :data:`RESTART_MAX_ITER` iterations (or the
    user's ``max_iter``, if fewer)."""
    return {**RESTART_OPTIONS, "ipopt.max_iter": min(options.max_iter, RESTART_MAX_ITER)}


#: IPOPT's tolerance for a held stage on a finer grid (the step length and speed held at the
#: coarser solution's) when its release follows (stage ``..., all free``): the held stage is
#: only the release's start, and the release starts its barrier at 1e-6 (the
#: transcription's warm-start options). Solved to the final tolerance, its point (at a
#: barrier of 1e-8) was first moved back to the 1e-6 barrier's central path by the release,
#: in 5-12 iterations; at 1e-5 IPOPT stops once the 1e-6 barrier problem is solved. The
#: five-link walk, 2 variants x 7 speeds (3-60 m/min): the fine stages took 698 instead of
#: 837 iterations in full coordinates on 40 + 10 knots (7.8 instead of 9.0 s) and 741
#: instead of 874 in the reduced formulation on the default grid, to the same optima
#: (largest relative difference 8e-11; ``docs/results/benchmarks-gait.md``). A user's ``tol``
#: above it applies instead, and a held stage that is the answer (speed and step length or
#: step time given) keeps the user's.
HELD_STAGE_TOL = 1e-5
#: IPOPT options of the check-grid stage (the cost error estimate's finer grid), started
#: from the target grid's optimum without multipliers: that start is closer to the check
#: grid's optimum than a coarse solution is to the target grid's, so the barrier starts at
#: 1e-8, the barrier the target grid's solve ended at. From 1e-6 IPOPT first moved the
#: start onto the 1e-6 central path and back, in 5-12 iterations: 2 variants x 7 speeds
#: (3-60 m/min), the check stages took 155 instead of 216 iterations in full coordinates
#: on 40 + 10 knots (checked on 60 + 15) and 214 instead of 233 in the reduced formulation
#: on the default grid; the check costs moved by at most 2e-7 relative, within the solve's
#: own accuracy (1e-6 against a solve to tol 1e-11, from either start). Earlier, 1e-6
#: against IPOPT's 1e-4: over the 80 default solves of the convergence grid (four variants,
#: 3-60 m/min, cosine 16 + 6 knots checked on 24 + 8) the check stages took 1,327 instead of
#: 1,962 iterations to the same optima (largest relative difference 1.6e-9); in full
#: coordinates (two variants at 3/12/24/48 m/min) 126 instead of 178. Only for the walk:
#: on the seven-link heel-toe walk (24 + 16 knots checked on 36 + 24) at 36 m/min it took 35
#: instead of 63 iterations but to another local optimum, 0.26 % dearer (2867.92 against
#: 2860.47), which would change the error estimate (at 12 m/min: 193 against 188, the same).
CHECK_GRID_OPTIONS = {**PRIMAL_WARM_OPTIONS, "ipopt.mu_init": 1e-8}
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
    at IPOPT's acceptable level, against 23 + 13 with the exact Hessian (12 m/min), and for
    the separated form, whose derivatives are assembled from compiled point functions
    (:func:`gaitopt.gait.solve.transcriptions.evaluation_mode`): its exact Hessian costs no
    derivation of the whole NLP (at 40 + 10: 38 + 18 iterations against 99 + 25)."""
    if (not formulation_of(options).traits.quasi_newton_fine_stages
            or options.transcription == "hermite-simpson-separated"):
        return {}
    return dict(FINE_STAGE_OPTIONS)


#: IPOPT options of every stage on a grid finer than the coarse one (the target grid and its
#: release, the check grid, mesh refinement, a warm start) of the two-phase walk, in either
#: formulation: IPOPT takes MUMPS's solution of each step's linear system as it is
#: (``fast_step_computation``: no residuals, no refinement back-solve to check it). Measured
#: by bench/linear_solver.py (docs/results/benchmarks-gait.md, "MUMPS ordering and IPOPT's step
#: options"): the fine stages took 0.92-0.94x the time on the reduced convergence grid
#: (80/80 points, 4,769 against 4,783 iterations) and 0.88-0.92x on the full-coordinate
#: sample (40/40, 2,481 against 2,482), the optima equal to 3e-12. Not for the heel-toe walk
#: (0.986x, and 515 instead of 474 iterations at 36 m/min) nor other contact sequences,
#: where it was not measured. What is given up is IPOPT's check of a step's accuracy (and
#: the larger pivot tolerance it asks for after a poor one); no point failed or moved
#: without it.
WALK_FINE_GRID_OPTIONS: dict[str, Any] = {"ipopt.fast_step_computation": "yes"}
#: Added to :data:`WALK_FINE_GRID_OPTIONS` for the walk in full coordinates: MUMPS without
#: its permuting scaling (the MC64 matching, which MUMPS otherwise chooses itself, computes
#: once per analysis and reuses; without it MUMPS scales at every factorization). Measured
#: by bench/linear_solver.py (docs/results/benchmarks-gait.md, "MUMPS scaling"): on these stages the
#: same iterations to the same optima (40/40 points, 3-60 m/min, both ankle variants,
#: relative cost differences below 3e-13), each iteration cheaper: the target grid 0.92x,
#: the check grid 0.88x on the default 16 + 6 grid, 0.81x on uniform 40 + 10. Not elsewhere:
#: the coarse stages change their path with it (for better or worse), the reduced
#: formulation and the heel-toe walk gain nothing, and on the reduced walk's fine stages two
#: of the 80 convergence-grid points then failed.
FULL_WALK_FINE_GRID_OPTIONS: dict[str, Any] = {"ipopt.mumps_permuting_scaling": 0}


def fine_grid_options(options: GaitOptions) -> dict[str, Any]:
    """The IPOPT options of the stages on grids finer than the coarse one: for the two-phase
    walk :data:`WALK_FINE_GRID_OPTIONS`, in full coordinates with
    :data:`FULL_WALK_FINE_GRID_OPTIONS`; none for other contact sequences."""
    if sequence_kind(options) != "walk":
        return {}
    if formulation_of(options).traits.unscaled_mumps_fine_walk:
        return {**WALK_FINE_GRID_OPTIONS, **FULL_WALK_FINE_GRID_OPTIONS}
    return dict(WALK_FINE_GRID_OPTIONS)


def sequence_kind(options: GaitOptions) -> str:
    """The contact sequence of ``options`` by kind, which stage settings are chosen by: its
    ``gait`` (``walk``, ``run``, ``heel-toe``), or ``"sequence"`` for a given
    ``contact_sequence``."""
    return options.gait if options.contact_sequence is None else "sequence"


def held_stage_options(options: GaitOptions, released: bool) -> dict[str, Any]:
    """The IPOPT options of a held stage on a finer grid: :data:`PRIMAL_WARM_OPTIONS` with
    :func:`fine_stage_options` merged over them and, when its release follows
    (``released``), the tolerance :data:`HELD_STAGE_TOL` (or the user's, if looser)."""
    out = {**PRIMAL_WARM_OPTIONS, **fine_stage_options(options)}
    if released:
        out["ipopt.tol"] = max(options.tol, HELD_STAGE_TOL)
    return out


def check_grid_options(options: GaitOptions) -> dict[str, Any]:
    """The IPOPT options of the check-grid stage: :data:`CHECK_GRID_OPTIONS` for the walk
    (two phases), :data:`PRIMAL_WARM_OPTIONS` for other contact sequences; with
    :func:`fine_stage_options` merged over them."""
    walk = sequence_kind(options) == "walk"
    return {**(CHECK_GRID_OPTIONS if walk else PRIMAL_WARM_OPTIONS),
            **fine_stage_options(options)}


def coarse_knots(options: GaitOptions) -> tuple[int, int]:
    """The grid of the first stages: the requested one, at most the paper's 8 + 5 (knots
    given per phase: the first phase's and the fewest of the others')."""
    knots = options.knots
    return (min(8, knots[0]), min(5, min(knots[1:]) if len(knots) > 1 else knots[0]))


#: What the release stages free besides parameters: the ankle torques (held at zero before).
ANKLES = "ankle torques"
#: The control model of the contact stages (from the naive guess) and of the continuation in
#: speed: the paper's, whatever the requested one (:mod:`gaitopt.gait.solve.staged`).
COLD_CONTROL_MODEL: ControlModel = "paper"


@dataclass(frozen=True)
class StageSpec:
    """One continuation stage as data: its name (``{control_model}`` stands for the
    requested one), whether it runs for the options, the contact relaxation, the quantity it
    frees (:data:`ANKLES` or a parameter name; every earlier stage holds it), IPOPT options
    merged over the transcription's, those (for the options) merged over the warm-start
    options when it starts from a solution's multipliers
    (:meth:`gaitopt.ocp.Transcription.solve`; None: the transcription's own), and what
    it starts from: the previous stage's solution with its multipliers, or
    (``values_only``) its values alone, for a stage whose NLP differs from the previous
    one's (the later stages then hold at this stage's values)."""

    name: str
    runs: Callable[[GaitOptions], bool] = lambda options: True
    relax: Relaxation = Relaxation()
    frees: str | None = None
    solver_options: dict[str, Any] | None = None
    warm_start_options: Callable[[GaitOptions], dict[str, Any] | None] = lambda options: None
    values_only: bool = False

    def title(self, options: GaitOptions) -> str:
        """The stage's name for ``options`` (as printed and kept in the solution)."""
        return self.name.format(control_model=options.control_model)


#: Stages 1-2, on the coarse grid from each naive guess, everything in :data:`RELEASES`
#: held: the contact conditions relaxed, then enforced (the paper's two-stage process).
CONTACT_STAGES: tuple[StageSpec, ...] = (
    StageSpec("relaxed contact", relax=RELAXED, solver_options=COLD_START_OPTIONS),
    StageSpec("enforced contact", warm_start_options=lambda o: (
        ENFORCED_CONTACT_OPTIONS if formulation_of(o).traits.warm_enforced_contact else None)),
)
#: Stage 3: what the contact stages held, freed one at a time in this order (the impulse
#: from the no-impulse gait keeps the impulse variants out of worse local minima).
RELEASES: tuple[StageSpec, ...] = (
    StageSpec("ankle torques free", runs=lambda o: o.ankle, frees=ANKLES),
    StageSpec("liftoff impulse free", runs=lambda o: o.impulse and o.double_support,
              frees=IMPULSE),
    StageSpec("phase fractions free", runs=lambda o: frees_fractions(o), frees=FRACTION),
    StageSpec("speed free", runs=lambda o: o.speed is None, frees=SPEED),
)


#: The coarse problem of the contact stages solved again in the requested control model, from
#: their solution's values (feasible for it: the jumps model only drops the control linkages;
#: the multipliers belong to the other NLP), when it is not :data:`COLD_CONTROL_MODEL`.
CONTROL_MODEL_STAGE = StageSpec(
    "control model {control_model}",
    runs=lambda o: o.control_model != COLD_CONTROL_MODEL,
    solver_options=PRIMAL_WARM_OPTIONS, values_only=True)
#: What a coarse solution of the contact stages goes through on the coarse grid, in order.
COARSE_COMPLETION: tuple[StageSpec, ...] = (CONTROL_MODEL_STAGE, *RELEASES)


def frees_fractions(options: GaitOptions) -> bool:
    """Whether the options free phase fractions (``single_support_fraction_bounds``,
    ``free_phase_fractions`` or fraction bounds in a given sequence)."""
    if options.single_support_fraction_bounds is not None or options.free_phase_fractions:
        return True
    if options.contact_sequence is None:
        return False
    return bool(free_phases(sequence_from_dict(options.contact_sequence)))


def held_bounds(options: GaitOptions, held: set[str], speed: float,
                result: Result | None = None,
                fractions: Mapping[str, float] | None = None) -> dict[str, Any]:
    """The parameter bounds with the quantities in ``held`` held: the speed at ``speed``, the
    impulse at 0, the free phase fractions (``fractions``: parameter name -> first guess,
    :func:`gaitopt.gait.sequence.phase_fractions.fraction_parameters`) at ``result``'s values or at
    their guesses; the ankle torques are held by the stage."""
    bounds = dict(parameter_bounds(options))
    if SPEED in held:
        bounds[SPEED] = (speed, speed)
    if IMPULSE in held:
        bounds[IMPULSE] = (0.0, 0.0)
    if FRACTION in held:
        for name, guess in (fractions or {}).items():
            value = result.parameters.get(name, guess) if result is not None else guess
            bounds[name] = (value, value)
    return bounds


def held_ankles(model: RobotModel, tr: Transcription, bounds: Bounds) -> Bounds:
    """``bounds`` with every ankle torque of every phase bounded to zero."""
    ankles = {a.name for a in model.actuators if a.contact is not None}
    for ph in tr.problem.phases:
        for name in ph.controls:
            if name in ankles:
                bounds = bounds.with_control(ph.name, name, 0.0, 0.0)
    return bounds
