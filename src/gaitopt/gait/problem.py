"""The paper's minimum-energy walking problem stated on the generic OCP engine.

(One concept, kept whole at about 450 lines: :func:`walking_problem` states the whole OCP of
the reduced formulation with its stage bounds; the helpers serve it alone.)

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
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.kinematics import contact_velocity, point_position
from gaitopt.gait import cost, walking
from gaitopt.gait.model_scale import ModelScale, model_scale
from gaitopt.gait.options import GaitOptions
from gaitopt.gait.walking import DOUBLE, SINGLE
from gaitopt.ocp.bounds import Bounds
from gaitopt.ocp.problem import (
    BoundaryConstraint,
    ControlLinkage,
    Duration,
    Linkage,
    Parameter,
    PathConstraint,
    Phase,
    Problem,
)
from gaitopt.ocp.transcription import Transcription
from gaitopt.robot.biped import reduced_biped
from gaitopt.robot.model import RobotModel

STEP_LENGTH, SPEED, IMPULSE = "step_length", "speed", "impulse"
#: What the stage ``phase fractions free`` frees: the free phase fractions of the full
#: formulation (its parameters ``fraction_<phase>``,
#: :func:`gaitopt.gait.phase_fractions.fraction_parameters`; bounded there, not here).
FRACTION = "phase fractions"
PARAMETERS = (STEP_LENGTH, SPEED, IMPULSE)
_L, _V, _P = range(3)

#: Largest forward lean of the virtual stance leg considered (rad), a generous box on alpha.
ALPHA_BOUND = 1.3

# Names of the unilateral contact conditions (relaxed by the first continuation stage).
SS_FORCE = "stance contact force"
DS_FORCES = "double support contact forces"
STRIKE_IMPULSES = "heel strike normal impulses"
LIFTOFF_CONDITIONS = "liftoff: held normal impulse, lifting tip rises"
STRIKE_ALONE = "heel strike: normal impulse, trailing tip rises"
EVENT_FRICTION = "friction cones of the event impulses"
#: The step time ``L / v`` (s): a row of the NLP when a step time is given, bounded by
#: :func:`with_step_time`, so problems with different step times share one NLP. Problems
#: without a step time have no such row: even a free row changes IPOPT's path (a warm start in
#: a speed sweep took 353 iterations instead of 79 with it).
STEP_TIME = "step time L / v"


@dataclass(frozen=True)
class Relaxation:
    """How far the unilateral contact conditions may be violated (N, N s): 0 enforces them.

    The continuation solves a relaxed problem first (the paper's two-stage process). The
    relaxation is applied through the bounds of those rows (:func:`relaxed_bounds`), so
    the relaxed and the enforced problem share one NLP."""

    force: float = 0.0
    impulse: float = 0.0


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


def with_step_time(bounds: Bounds, options: GaitOptions) -> Bounds:
    """``bounds`` with the step-time row fixed to ``options.step_time`` (s), if given."""
    if options.step_time is None:
        return bounds
    return bounds.with_constraint(STEP_TIME, options.step_time, options.step_time)


def parameter_bounds(options: GaitOptions) -> dict[str, tuple[float, float]]:
    """Bounds of ``L, v, P`` for a variant: a given value becomes equal bounds. (Free phase
    fractions keep the bounds their parameters have in the problem.)"""
    if options.step_length is not None:
        step = (options.step_length, options.step_length)
    elif options.step_time is not None and options.speed is not None:
        implied = options.step_time * options.speed
        step = (implied, implied)
    else:
        step = options.step_length_bounds
    speed = options.speed_bounds if options.speed is None else (options.speed, options.speed)
    # Without double support the trailing leg leaves at the heel strike with no impulse.
    with_impulse = options.impulse and options.double_support
    impulse = (0.0, options.max_impulse) if with_impulse else (0.0, 0.0)
    return {STEP_LENGTH: step, SPEED: speed, IMPULSE: impulse}


#: Scale (m) of the constraints that are lengths (tip heights, landing positions) on the
#: reference biped (1 m legs); ``l / l_ref`` times it on another model.
LENGTH_SCALE = 0.1
#: Scales of the parameters on the reference biped: step length (m), speed (m/s), liftoff
#: impulse (N s); carried over as a length, a speed and an impulse
#: (:mod:`gaitopt.gait.model_scale`).
STEP_LENGTH_SCALE, SPEED_SCALE, IMPULSE_SCALE = 0.5, 1.0, 5.0


def parameters_of(bounds: Mapping[str, tuple[float, float]], scale: ModelScale
                  ) -> list[Parameter]:
    """The step length, speed and impulse parameters within ``bounds``, scaled for the model
    of ``scale`` (:data:`STEP_LENGTH_SCALE`, :data:`SPEED_SCALE`, :data:`IMPULSE_SCALE`)."""
    return [Parameter(STEP_LENGTH, *bounds[STEP_LENGTH],
                      scale=scale.length(STEP_LENGTH_SCALE)),
            Parameter(SPEED, *bounds[SPEED], scale=scale.speed(SPEED_SCALE)),
            Parameter(IMPULSE, *bounds[IMPULSE], scale=scale.impulse(IMPULSE_SCALE))]


def _limits(model: RobotModel, joint: str) -> tuple[float, float]:
    for j in model.joints:
        if j.name == joint:
            return j.limits
    raise KeyError(joint)


def walking_problem(model: RobotModel, options: GaitOptions) -> Problem:
    """The OCP of one periodic step for ``model`` with ``options`` (see the module docstring).

    Call :func:`gaitopt.gait.options.validate_options` first.
    """
    legs = reduced_biped(model).legs
    stance, swing = legs
    f = options.single_support_fraction
    two_phases = options.double_support
    r_max = min(leg.reach(-options.min_stance_knee_flexion) for leg in legs)
    # the shortest reach within the knee's range: at its lower limit, or folded at -pi if the
    # knee bends further (an unbounded knee's limit is -inf)
    r_min = max(leg.reach(max(_limits(model, leg.knee)[0], -math.pi)) for leg in legs)
    rate = options.rate_bound
    sc = model_scale(model)
    mu = options.friction
    # Lower bound of the normal impulses on held tips at the events (the paper's maps: none).
    impulse_floor = 0.0 if options.unilateral_impulses else -ca.inf

    ss_states = walking.state_names(model, SINGLE)
    ss_controls = walking.control_names(model, SINGLE, ankle=options.ankle)
    ds_states = walking.state_names(model, DOUBLE)
    ds_controls = walking.control_names(model, DOUBLE, ankle=options.ankle)

    def control_bounds(names: Sequence[str]) -> dict[str, tuple[float, float]]:
        return {n: model.actuators[model.actuator_index(n)].limits for n in names}

    def state_bounds(names: Sequence[str]) -> dict[str, tuple[float, float]]:
        bounds: dict[str, tuple[float, float]] = {
            "r": (r_min, r_max), "alpha": (-ALPHA_BOUND, ALPHA_BOUND),
            "torso": options.torso_bounds}
        for leg in legs:
            bounds[leg.hip] = _limits(model, leg.hip)
            bounds[leg.knee] = _limits(model, leg.knee)
        for n in names:
            if n.endswith("_rate"):
                # The hip's radial rate (m/s): the rate bound times the leg length ratio.
                v = sc.length(rate) if n == "r_rate" else rate
                bounds[n] = (-v, v)
        return {n: bounds[n] for n in names}

    paper_cost = options.cost == "paper" and options.cost_regularization == 0.0
    rate_weights = cost.torque_rate_weights(model, options)

    def running(point: Callable[[Any, Any, Any], walking.PhasePoint],
                controls: Sequence[str]) -> Callable[[Any, Any, Any, Any], Any]:
        """The running cost of a phase: ``u'u`` (paper) or :func:`cost.running_cost`."""
        def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
            if paper_cost:
                return ca.sumsqr(u)
            return cost.running_cost(model, options, point(x, u, p).solution.qd,
                                     walking.full_controls(model, controls, u), p)
        return fn

    # -- phase 1: single support on leg 1 ----------------------------------------------------
    ss = _PointCache(lambda x, u, p: walking.single_support_point(model, x, u, ss_controls))

    def ss_dynamics(x: Any, u: Any, p: Any, t: Any) -> Any:
        return ss(x, u, p).xdot

    def ss_contact(x: Any, u: Any, p: Any, t: Any) -> Any:
        fx, fy = as_scalars(ss(x, u, p).solution.forces, 2, "forces")
        rows = [fy]
        if mu is not None:
            rows += [mu * fy - fx, mu * fy + fx]
        return vector(rows)

    def ss_geometry(x: Any, u: Any, p: Any, t: Any) -> Any:
        q = ss(x, u, p).solution.q
        qs = as_scalars(q, model.nq, "q")
        return vector([walking.tip_height(model, q, swing), qs[stance.hip_index]])

    hip_lo, hip_hi = _limits(model, stance.hip)
    ss_path = [
        PathConstraint(SS_FORCE, ss_contact, lower=0.0, upper=ca.inf,
                       scale=model.total_mass * 9.81),
        PathConstraint("swing clearance and stance hip limit", ss_geometry,
                       lower=[0.0, hip_lo], upper=[ca.inf, hip_hi],
                       scale=[sc.length(LENGTH_SCALE), 1.0]),
    ]
    if options.swing_clearance is not None:
        ss_path.append(_clearance_constraint(model, swing, options.swing_clearance,
                                             options.clearance_profile, f,
                                             lambda x, u, p: ss(x, u, p).solution.q))
    phase1 = Phase(
        name=SINGLE, states=ss_states, controls=ss_controls, dynamics=ss_dynamics,
        duration=Duration.of_parameters(lambda p: f * p[_L] / p[_V]),
        state_bounds=state_bounds(ss_states), control_bounds=control_bounds(ss_controls),
        path_constraints=ss_path, lagrange=running(ss, ss_controls),
        control_rate_weights={n: r for n, r in rate_weights.items() if n in ss_controls},
        intervals=options.knots[0] - 1)

    phases = [phase1]
    linkages: list[Linkage | ControlLinkage] = []
    events: list[BoundaryConstraint] = []

    def landing(ends: Mapping[str, Any], p: Any) -> Any:
        q, _ = walking.single_support_to_full(model, ends[SINGLE].xf)
        c = model.contact(swing.contact)

        tip = as_scalars(point_position(model, q, c.link, model.link(c.link).local_point(*c.at)),
                         2, "tip")
        return vector([tip[0] - p[_L], tip[1]])

    events.append(BoundaryConstraint("swing tip lands at (L, 0)", landing, 0.0, 0.0,
                                     scale=sc.length(LENGTH_SCALE)))
    if options.step_time is not None:
        events.append(BoundaryConstraint(STEP_TIME, lambda ends, p: p[_L] / p[_V],
                                         lower=-ca.inf, upper=ca.inf, scale=1.0))

    def strike(ends: Mapping[str, Any], p: Any) -> walking.Transition:
        return walking.heel_strike(model, ends[SINGLE].xf, p[_L], double_support=two_phases)

    def lift(ends: Mapping[str, Any], p: Any) -> walking.Transition:
        return walking.liftoff(model, ends[DOUBLE].xf, p[_L], p[_P])

    def departure(tr: walking.Transition) -> Any:
        """At the event where tip 1 leaves the ground: the normal impulse on tip 2 (which
        stays) and the vertical velocity of tip 1 afterwards (it must rise)."""
        normal = as_scalars(tr.impulses[swing.contact], 2, "i")[1]
        v_up = walking.tip_vertical_velocity(model, tr.q, tr.qd_after, stance)
        return vector([normal, v_up])

    if mu is not None:
        def event_friction(ends: Mapping[str, Any], p: Any) -> Any:
            """``mu n -+ t >= 0`` for every impulse of the ground on a held tip."""
            held = list(strike(ends, p).impulses.values())
            if two_phases:
                held.append(lift(ends, p).impulses[swing.contact])
            rows = []
            for impulse in held:
                t_imp, n_imp = as_scalars(impulse, 2, "impulse")
                rows += [mu * n_imp - t_imp, mu * n_imp + t_imp]
            return vector(rows)

        events.append(BoundaryConstraint(EVENT_FRICTION, event_friction, lower=0.0,
                                         upper=ca.inf, scale=1.0))

    if two_phases:
        ds = _PointCache(
            lambda x, u, p: walking.double_support_point(model, x, u, ds_controls, p[_L]))

        def ds_dynamics(x: Any, u: Any, p: Any, t: Any) -> Any:
            return ds(x, u, p).xdot

        def ds_contact(x: Any, u: Any, p: Any, t: Any) -> Any:
            fx1, fy1, fx2, fy2 = as_scalars(ds(x, u, p).solution.forces, 4, "forces")
            rows = [fy1, fy2]
            if mu is not None:
                rows += [mu * fy1 - fx1, mu * fy1 + fx1, mu * fy2 - fx2, mu * fy2 + fx2]
            return vector(rows)

        def ds_geometry(x: Any, u: Any, p: Any, t: Any) -> Any:
            qs = as_scalars(ds(x, u, p).solution.q, model.nq, "q")
            return vector([walking.front_leg_reach(x, p[_L]), qs[stance.hip_index],
                           qs[swing.hip_index]])

        sw_lo, sw_hi = _limits(model, swing.hip)
        ds_path = [
            PathConstraint(DS_FORCES, ds_contact, lower=0.0,
                           upper=ca.inf, scale=model.total_mass * 9.81),
            PathConstraint("front leg reach and hip limits", ds_geometry,
                           lower=[r_min, hip_lo, sw_lo], upper=[r_max, hip_hi, sw_hi]),
        ]
        phase2 = Phase(
            name=DOUBLE, states=ds_states, controls=ds_controls, dynamics=ds_dynamics,
            duration=Duration.of_parameters(lambda p: (1.0 - f) * p[_L] / p[_V]),
            state_bounds=state_bounds(ds_states), control_bounds=control_bounds(ds_controls),
            path_constraints=ds_path, lagrange=running(ds, ds_controls),
            control_rate_weights={n: r for n, r in rate_weights.items() if n in ds_controls},
            intervals=options.knots[1] - 1)
        phases.append(phase2)

        linkages.append(Linkage(
            SINGLE, DOUBLE, name="heel strike (impact, tip 1 held)",
            jump=lambda xf, uf, p: walking.heel_strike(model, xf, p[_L],
                                                       double_support=True).x_next))

        def strike_impulses(ends: Mapping[str, Any], p: Any) -> Any:
            imp = strike(ends, p).impulses
            return vector([as_scalars(imp[stance.contact], 2, "i")[1],
                           as_scalars(imp[swing.contact], 2, "i")[1]])

        events.append(BoundaryConstraint(STRIKE_IMPULSES, strike_impulses,
                                         lower=impulse_floor, upper=ca.inf, scale=1.0))

        linkages.append(Linkage(
            DOUBLE, SINGLE, name="liftoff impulse and periodicity (legs relabelled)",
            jump=lambda xf, uf, p: walking.liftoff(model, xf, p[_L], p[_P]).x_next))

        events.append(BoundaryConstraint(LIFTOFF_CONDITIONS,
                                         lambda ends, p: departure(lift(ends, p)),
                                         lower=[impulse_floor, 0.0],
                                         upper=ca.inf, scale=[1.0, 0.1]))
        # Controls (paper model): continuous across the heel strike, periodic with legs
        # relabelled. The "jumps" model has no control linkages.
        if options.control_model == "paper":
            shared = [n for n in ss_controls if n in ds_controls]
            linkages.append(ControlLinkage(SINGLE, DOUBLE, controls=shared,
                                           name="controls continuous at heel strike"))
        if options.periodic_controls and options.control_model == "paper":
            linkages.append(_periodic_controls(model, DOUBLE, ds_controls, ss_controls))
    else:
        linkages.append(Linkage(
            SINGLE, SINGLE, name="heel strike (tip 2 alone) and periodicity",
            jump=lambda xf, uf, p: walking.heel_strike(model, xf, p[_L],
                                                       double_support=False).x_next))

        events.append(BoundaryConstraint(STRIKE_ALONE,
                                         lambda ends, p: departure(strike(ends, p)),
                                         lower=[impulse_floor, 0.0],
                                         upper=ca.inf, scale=[1.0, 0.1]))
        if options.periodic_controls and options.control_model == "paper":
            linkages.append(_periodic_controls(model, SINGLE, ss_controls, ss_controls))

    bounds = parameter_bounds(options)
    parameters = parameters_of(bounds, sc)
    return Problem(
        phases=phases, parameters=parameters, linkages=linkages, boundary_constraints=events,
        parameter_cost=(lambda p: p[_P] ** 2) if options.cost == "paper" else
        (lambda p: cost.parameter_cost(model, options, p)),
        mayer=None if options.cost == "paper" or not two_phases else
        (lambda ends, p: liftoff_cost(model, options, lift(ends, p), p[_P])),
        cost_denominator=lambda ends, p: cost.denominator(model, options, p),
        objective_scale=cost.objective_scale(options, sc))


def liftoff_cost(model: RobotModel, options: GaitOptions, tr: walking.Transition,
                 magnitude: Any) -> Any:
    """The cost term of the liftoff impulse (:func:`cost.impulse_cost`) from its transition."""
    lifting = reduced_biped(model).stance.contact

    v_after = contact_velocity(model, tr.q, tr.qd_after, lifting)
    return cost.impulse_cost(model, options, tr.impulses[lifting], v_after, magnitude)


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


def _periodic_controls(model: RobotModel, from_phase: str, from_controls: Sequence[str],
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


#: Name of the swing clearance profile constraint (see :func:`clearance_profile`).
CLEARANCE = "swing clearance profile"


def clearance_profile(clearance: float, s: Any, profile: str) -> Any:
    """The least swing-tip height (m) at normalised single-support time ``s`` in [0, 1]:
    ``c 4 s (1 - s)`` (``"parabola"``) or ``c (4 s (1 - s))^2`` (``"quartic"``); both are 0
    at the liftoff and the heel strike and ``c`` at mid-swing. The parabola's slope at the
    ends, ``4 c / T1``, is a least vertical tip velocity at both events; the quartic's is
    zero."""
    bump = 4.0 * s * (1.0 - s)
    return clearance * (bump if profile == "parabola" else bump * bump)


def _clearance_constraint(model: RobotModel, swing: Any, clearance: float, profile: str,
                          fraction: float,
                          configuration: Callable[[Any, Any, Any], Any]) -> PathConstraint:
    """``y_tip(q) - profile(s) >= 0`` over single support, with ``s = t / T1`` and
    ``T1 = f L / v`` (single support starts the step at ``t = 0``)."""

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        s = t * p[_V] / (fraction * p[_L])
        return walking.tip_height(model, configuration(x, u, p), swing) \
            - clearance_profile(clearance, s, profile)

    return PathConstraint(CLEARANCE, fn, lower=0.0, upper=ca.inf,
                          scale=model_scale(model).length(LENGTH_SCALE))
