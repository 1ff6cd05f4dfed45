"""The paper's minimum-energy walking problem stated on the generic OCP engine.

Decision parameters ``p = [step_length L, speed v, impulse P]``; phase durations are
expressions of them: ``T1 = f L / v`` (single support) and ``T2 = (1 - f) L / v`` (double
support), ``f`` the single-support fraction. The objective is the paper's eq. 5::

    J = ( int_0^T1 u'u dt + int_T1^T u'u dt + P^2 ) / L

Constraints (``docs/walking.md`` lists each with its reason): torque bounds, joint limits, the
polar box ``r_min <= r <= r_max`` on the stance leg, the swing tip above the ground, normal
contact forces ``>= 0`` at knots and midpoints, normal impulses ``>= 0`` at the heel
strike and the liftoff, the lifting tip moving up after liftoff, tip 2 landing at ``(L, 0)``,
the front leg's reach in double support, optional friction cones, an optional swing clearance
profile, periodicity of states (through the liftoff map) and, with the paper's control model,
continuity of controls between the phases and their periodicity with the legs relabelled.

:func:`walking_problem` lists the parts of the problem; each is built by a named function:
the phases (:func:`single_support_phase`, :func:`double_support_phase`: their
:func:`state_bounds`, :func:`control_bounds`, :func:`running_cost` and path constraints), the
event maps and control linkages (:func:`step_linkages`), the parameters
(:func:`parameter_bounds`, :func:`parameters_of`) and the objective's terms. The constraint
blocks themselves are built in :mod:`gaitopt.gait.formulations.reduced.constraints`, one
function each. :func:`relaxed_bounds` gives the stages' bounds.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import casadi as ca
import numpy as np

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.kinematics import contact_velocity
from gaitopt.gait.formulations import cost
from gaitopt.gait.formulations.reduced import physics as walking
from gaitopt.gait.formulations.reduced.constraints import (
    DS_FORCES,
    EVENT_FRICTION,
    LIFTOFF_CONDITIONS,
    SS_FORCE,
    STRIKE_ALONE,
    STRIKE_IMPULSES,
    PointFn,
    double_support_path,
    event_constraints,
    joint_limits,
    leg_reach,
    liftoff_at,
    single_support_path,
)
from gaitopt.gait.formulations.reduced.physics import DOUBLE, SINGLE
from gaitopt.gait.formulations.step_parameters import (
    IMPULSE_INDEX,
    SPEED_INDEX,
    STEP_LENGTH_INDEX,
    Relaxation,
    parameter_bounds,
    parameters_of,
)
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.ocp.bounds import Bounds
from gaitopt.ocp.problem import (
    ControlLinkage,
    Duration,
    Linkage,
    PathConstraint,
    Phase,
    Problem,
)
from gaitopt.ocp.transcription import Transcription
from gaitopt.robot.biped import reduced_biped
from gaitopt.robot.model import RobotModel

_L, _V, _P = STEP_LENGTH_INDEX, SPEED_INDEX, IMPULSE_INDEX

#: Largest forward lean of the virtual stance leg considered (rad), a generous box on alpha.
ALPHA_BOUND = 1.3


def walking_problem(model: RobotModel, options: GaitOptions) -> Problem:
    """The OCP of one periodic step for ``model`` with ``options`` (see the module docstring).

    Call :func:`gaitopt.gait.options.gait_options.validate_options` first.
    """
    two_phases = options.double_support
    phases = [single_support_phase(model, options)]
    if two_phases:
        phases.append(double_support_phase(model, options))
    paper = options.cost == "paper"
    return Problem(
        phases=phases,
        parameters=parameters_of(parameter_bounds(options), model_scale(model)),
        linkages=step_linkages(model, options),
        boundary_constraints=event_constraints(model, options),
        parameter_cost=(lambda p: p[_P] ** 2) if paper else
        (lambda p: cost.parameter_cost(model, options, p)),
        mayer=None if paper or not two_phases else
        (lambda ends, p: liftoff_cost(model, options, liftoff_at(model, ends, p), p[_P])),
        cost_denominator=lambda ends, p: cost.denominator(model, options, p),
        objective_scale=cost.objective_scale(options, model_scale(model)))


class _PointCache:
    """Evaluate a phase's dynamics once per symbolic point and share the result between the
    dynamics, the path constraints and the cost (the engine calls each with the same
    symbols)."""

    def __init__(self, compute: Callable[[Any, Any, Any], walking.PhasePoint]) -> None:
        self._compute = compute
        self._key: tuple[Any, Any, Any] | None = None
        self._value: walking.PhasePoint | None = None

    def __call__(self, x: Any, u: Any, p: Any) -> walking.PhasePoint:
        key = self._key
        if key is None or not (key[0] is x and key[1] is u and key[2] is p):
            self._value = self._compute(x, u, p)
            self._key = (x, u, p)
        assert self._value is not None
        return self._value

    def dynamics(self, x: Any, u: Any, p: Any, t: Any) -> Any:
        """The phase's ``xdot = [zd, zdd]`` at ``(x, u, p)``, for :class:`Phase`."""
        return self(x, u, p).xdot


def state_bounds(model: RobotModel, options: GaitOptions, names: Sequence[str]
                 ) -> dict[str, tuple[float, float]]:
    """The box on the states ``names`` of a phase: the stance leg's polar coordinates ``r``
    within :func:`~gaitopt.gait.formulations.reduced.constraints.leg_reach` (m) and
    ``|alpha| <= ALPHA_BOUND`` (rad), the torso within ``options.torso_bounds`` (rad), the
    hips and knees within their joint limits (rad), and every rate within
    ``options.rate_bound`` (rad/s; the hip's radial rate ``r_rate`` in m/s, the rate bound
    times the leg length ratio)."""
    r_min, r_max = leg_reach(model, options)
    rate = options.rate_bound
    bounds: dict[str, tuple[float, float]] = {
        "r": (r_min, r_max), "alpha": (-ALPHA_BOUND, ALPHA_BOUND),
        "torso": options.torso_bounds}
    for leg in reduced_biped(model).legs:
        bounds[leg.hip] = joint_limits(model, leg.hip)
        bounds[leg.knee] = joint_limits(model, leg.knee)
    for n in names:
        if n.endswith("_rate"):
            v = model_scale(model).length(rate) if n == "r_rate" else rate
            bounds[n] = (-v, v)
    return {n: bounds[n] for n in names}


def control_bounds(model: RobotModel, names: Sequence[str]) -> dict[str, tuple[float, float]]:
    """The torque limits (N m) of the actuators ``names``."""
    return {n: model.actuators[model.actuator_index(n)].limits for n in names}


def running_cost(model: RobotModel, options: GaitOptions, point: PointFn,
                 controls: Sequence[str]) -> Callable[[Any, Any, Any, Any], Any]:
    """The running cost of a phase, ``(x, u, p, t) ->`` the paper's ``u'u`` (N^2 m^2) or
    :func:`cost.running_cost` of the joint rates and the torques (``options.cost``)."""
    paper_cost = options.cost == "paper" and options.cost_regularization == 0.0

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        if paper_cost:
            return ca.sumsqr(u)
        return cost.running_cost(model, options, point(x, u, p).solution.qd,
                                 walking.full_controls(model, controls, u), p)
    return fn


def phase_with(model: RobotModel, options: GaitOptions, name: str, point: _PointCache,
               controls: Sequence[str], path: list[PathConstraint],
               duration: Callable[[Any], Any], knots: int) -> Phase:
    """The phase ``name`` (:data:`SINGLE` or :data:`DOUBLE`) of ``knots`` knots with the
    dynamics ``point``, the actuators ``controls``, the path constraints ``path`` and
    ``duration(p)`` (s): its states and their :func:`state_bounds`, the
    :func:`control_bounds`, the :func:`running_cost` and the torque-rate weights."""
    states = walking.state_names(model, name)
    return Phase(
        name=name, states=states, controls=tuple(controls), dynamics=point.dynamics,
        duration=Duration.of_parameters(duration),
        state_bounds=state_bounds(model, options, states),
        control_bounds=control_bounds(model, controls), path_constraints=path,
        lagrange=running_cost(model, options, point, controls),
        control_rate_weights={n: r for n, r in cost.torque_rate_weights(model, options).items()
                              if n in controls},
        intervals=knots - 1)


def single_support_phase(model: RobotModel, options: GaitOptions) -> Phase:
    """Single support on leg 1 for ``T1 = f L / v`` (s), the reduced dynamics
    (:func:`walking.single_support_point`) and the path constraints of
    :func:`~gaitopt.gait.formulations.reduced.constraints.single_support_path`."""
    controls = walking.control_names(model, SINGLE, ankle=options.ankle)
    point = _PointCache(lambda x, u, p: walking.single_support_point(model, x, u, controls))
    f = options.single_support_fraction
    return phase_with(model, options, SINGLE, point, controls,
                      single_support_path(model, options, point),
                      lambda p: f * p[_L] / p[_V], options.knots[0])


def double_support_phase(model: RobotModel, options: GaitOptions) -> Phase:
    """Double support with tip 2 at ``(L, 0)`` for ``T2 = (1 - f) L / v`` (s), the reduced
    dynamics (:func:`walking.double_support_point`) and the path constraints of
    :func:`~gaitopt.gait.formulations.reduced.constraints.double_support_path`."""
    controls = walking.control_names(model, DOUBLE, ankle=options.ankle)
    point = _PointCache(
        lambda x, u, p: walking.double_support_point(model, x, u, controls, p[_L]))
    f = options.single_support_fraction
    return phase_with(model, options, DOUBLE, point, controls,
                      double_support_path(model, options, point),
                      lambda p: (1.0 - f) * p[_L] / p[_V], options.knots[1])


def step_linkages(model: RobotModel, options: GaitOptions) -> list[Linkage | ControlLinkage]:
    """The event maps and control linkages of a step, in order. With double support: the
    heel strike (tip 1 held, :func:`walking.heel_strike`), the liftoff with the impulse
    ``P`` and the relabelling (:func:`walking.liftoff`; the periodicity of the states), then
    with the paper's control model the controls continuous at the heel strike. Without: the
    heel strike of tip 2 alone, which is the periodicity. Then, with ``periodic_controls``
    and the paper's control model, the controls periodic (:func:`periodic_controls`). The
    "jumps" control model has no control linkages."""
    ss_controls = walking.control_names(model, SINGLE, ankle=options.ankle)
    ds_controls = walking.control_names(model, DOUBLE, ankle=options.ankle)
    paper = options.control_model == "paper"
    periodic = options.periodic_controls and paper
    linkages: list[Linkage | ControlLinkage] = []
    if options.double_support:
        linkages.append(Linkage(
            SINGLE, DOUBLE, name="heel strike (impact, tip 1 held)",
            jump=lambda xf, uf, p: walking.heel_strike(model, xf, p[_L],
                                                       double_support=True).x_next))
        linkages.append(Linkage(
            DOUBLE, SINGLE, name="liftoff impulse and periodicity (legs relabelled)",
            jump=lambda xf, uf, p: walking.liftoff(model, xf, p[_L], p[_P]).x_next))
        if paper:
            shared = [n for n in ss_controls if n in ds_controls]
            linkages.append(ControlLinkage(SINGLE, DOUBLE, controls=shared,
                                           name="controls continuous at heel strike"))
        if periodic:
            linkages.append(periodic_controls(model, DOUBLE, ds_controls, ss_controls))
    else:
        linkages.append(Linkage(
            SINGLE, SINGLE, name="heel strike (tip 2 alone) and periodicity",
            jump=lambda xf, uf, p: walking.heel_strike(model, xf, p[_L],
                                                       double_support=False).x_next))
        if periodic:
            linkages.append(periodic_controls(model, SINGLE, ss_controls, ss_controls))
    return linkages


def relabel_actuator(model: RobotModel, name: str) -> str | None:
    """The actuator of the other leg in the same role (hip_1 <-> hip_2, ...), or None."""
    legs = reduced_biped(model).legs
    for i, leg in enumerate(legs):
        other = legs[1 - i]
        for mine, theirs in ((leg.hip_actuator, other.hip_actuator),
                             (leg.knee_actuator, other.knee_actuator),
                             (leg.ankle_actuator, other.ankle_actuator)):
            if mine == name:
                return theirs
    return None


def periodic_controls(model: RobotModel, from_phase: str, from_controls: Sequence[str],
                      to_controls: Sequence[str]) -> ControlLinkage:
    """``u_first(0)[a] = u_last(T)[relabel(a)]`` for every control ``a`` whose relabelled
    counterpart acts at the end of the step."""
    targets = [a for a in to_controls if relabel_actuator(model, a) in from_controls]
    sources = [from_controls.index(relabel_actuator(model, a) or "") for a in targets]

    def fn(u_from: Any, p: Any) -> Any:
        us = as_scalars(u_from, len(from_controls), "u")
        return vector([us[i] for i in sources])

    return ControlLinkage(from_phase, SINGLE, fn=fn, controls=targets,
                          name="controls periodic (legs relabelled)")


def liftoff_cost(model: RobotModel, options: GaitOptions, tr: walking.Transition,
                 magnitude: Any) -> Any:
    """The cost term of the liftoff impulse (:func:`cost.impulse_cost`) from its transition."""
    lifting = reduced_biped(model).stance.contact

    v_after = contact_velocity(model, tr.q, tr.qd_after, lifting)
    return cost.impulse_cost(model, options, tr.impulses[lifting], v_after, magnitude)


def relaxed_bounds(tr: Transcription, relax: Relaxation) -> Bounds:
    """The transcription's bounds with the unilateral contact conditions relaxed by
    ``relax`` (lower bounds ``-relax.force`` on normal forces and friction rows,
    ``-relax.impulse`` on normal impulses)."""
    bounds = tr.bounds()
    if relax == Relaxation():
        return bounds

    def lower(b: Bounds, rows: Any, by: float) -> Bounds:
        # Only ever loosen: a row without a lower bound keeps none.
        return b.with_rows(rows, np.minimum(b.lbg[rows], -by), ca.inf)

    def block_rows(name: str, count: int | None = None) -> slice:
        rows = tr.nlp.constraints.block(name).rows
        return rows if count is None else slice(rows.start, rows.start + count)

    names = {ph.name for ph in tr.problem.phases}
    if SINGLE in names:
        bounds = lower(bounds, tr.path_rows(SINGLE, SS_FORCE), relax.force)
    if DOUBLE in names:
        bounds = lower(bounds, tr.path_rows(DOUBLE, DS_FORCES), relax.force)
        bounds = lower(bounds, block_rows(STRIKE_IMPULSES), relax.impulse)
        bounds = lower(bounds, block_rows(LIFTOFF_CONDITIONS, 1), relax.impulse)
    else:
        bounds = lower(bounds, block_rows(STRIKE_ALONE, 1), relax.impulse)
    if any(b.name == EVENT_FRICTION for b in tr.nlp.constraints.blocks):
        bounds = lower(bounds, block_rows(EVENT_FRICTION), relax.impulse)
    return bounds
