"""The constraint blocks of the reduced (paper's) walking problem, one named builder each.

:func:`gaitopt.gait.formulations.reduced.problem.walking_problem` assembles them: the path
constraints of each phase (:func:`single_support_path`, :func:`double_support_path`) and the
boundary constraints at the events (:func:`event_constraints`), in that order, which is the
order of the NLP's rows. ``docs/walking.md`` gives each constraint's reason.

Conventions of every builder: the world frame has ``x`` forward along the ground and ``y``
up, the ground at ``y = 0``; single support stands on tip 1 at the origin, double support
holds tip 2 at ``(L, 0)`` too. Lengths are in m, velocities in m/s, angles in rad, forces
in N (the ground's force on a tip, world ``(x, y)``), impulses in N s. ``x`` is a phase's
reduced state ``[z, zd]`` (:func:`gaitopt.gait.formulations.reduced.physics.state_names`),
``u`` its controls (N m), ``p = [L, v, P]`` the parameters (:data:`STEP_LENGTH_INDEX` ...),
``t`` the time (s) from the start of the phase. A path constraint's function takes
``(x, u, p, t)``; a phase's ``point`` takes ``(x, u, p)`` and returns the dynamics at that
point (:class:`~gaitopt.gait.formulations.reduced.physics.PhasePoint`, computed once per
point and shared with the dynamics and the cost). A boundary constraint's function takes
``(ends, p)``, ``ends[phase].xf`` the state at a phase's end.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import casadi as ca

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.kinematics import point_position
from gaitopt.gait.formulations.reduced import physics as walking
from gaitopt.gait.formulations.reduced.physics import DOUBLE, SINGLE
from gaitopt.gait.formulations.shared_rows import LENGTH_SCALE, clearance_profile, friction_rows
from gaitopt.gait.formulations.step_parameters import (
    IMPULSE_INDEX,
    SPEED_INDEX,
    STEP_LENGTH_INDEX,
    step_time_row,
)
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.ocp.problem import BoundaryConstraint, PathConstraint
from gaitopt.robot.biped import reduced_biped
from gaitopt.robot.model import RobotModel

_L, _V, _P = STEP_LENGTH_INDEX, SPEED_INDEX, IMPULSE_INDEX

# Names of the unilateral contact conditions (relaxed by the first continuation stage).
SS_FORCE = "stance contact force"
DS_FORCES = "double support contact forces"
STRIKE_IMPULSES = "heel strike normal impulses"
LIFTOFF_CONDITIONS = "liftoff: held normal impulse, lifting tip rises"
STRIKE_ALONE = "heel strike: normal impulse, trailing tip rises"
EVENT_FRICTION = "friction cones of the event impulses"
#: The swing tip above the ground and the stance hip within its limits (single support).
SS_GEOMETRY = "swing clearance and stance hip limit"
#: The front leg within reach and both hips within their limits (double support).
DS_GEOMETRY = "front leg reach and hip limits"
#: Name of the swing clearance profile constraint (see :func:`clearance_profile`).
CLEARANCE = "swing clearance profile"
#: The swing tip's landing point.
LANDING = "swing tip lands at (L, 0)"
#: A phase's dynamics at one point, ``(x, u, p) -> PhasePoint``.
PointFn = Callable[[Any, Any, Any], walking.PhasePoint]


def joint_limits(model: RobotModel, joint: str) -> tuple[float, float]:
    """The limits (rad) of the joint named ``joint``."""
    for j in model.joints:
        if j.name == joint:
            return j.limits
    raise KeyError(joint)


def leg_reach(model: RobotModel, options: GaitOptions) -> tuple[float, float]:
    """``(r_min, r_max)`` (m): the box on the hip-to-tip distance of a leg on the ground.
    ``r_max`` is the shorter leg's reach with the knee bent by
    ``options.min_stance_knee_flexion``; ``r_min`` the longer of the legs' shortest reaches
    within the knee's range: at its lower limit, or folded at ``-pi`` if the knee bends
    further (an unbounded knee's limit is ``-inf``)."""
    legs = reduced_biped(model).legs
    r_max = min(leg.reach(-options.min_stance_knee_flexion) for leg in legs)
    r_min = max(leg.reach(max(joint_limits(model, leg.knee)[0], -math.pi)) for leg in legs)
    return r_min, r_max


def stance_force_rows(model: RobotModel, friction: float | None, point: PointFn
                      ) -> PathConstraint:
    """:data:`SS_FORCE`, single support: ``f_y >= 0`` (N) for the ground's force ``(f_x,
    f_y)`` on tip 1, then with ``friction = mu`` its cone ``mu f_y -+ f_x >= 0``; 1 or 3
    rows, scaled by the model's weight ``m g`` (N)."""

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        fx, fy = as_scalars(point(x, u, p).solution.forces, 2, "forces")
        return vector([fy] + friction_rows(friction, fx, fy))

    return PathConstraint(SS_FORCE, fn, lower=0.0, upper=ca.inf,
                          scale=model.total_mass * 9.81)


def swing_clearance_and_hip_rows(model: RobotModel, point: PointFn) -> PathConstraint:
    """:data:`SS_GEOMETRY`, single support: ``[y_2(q) >= 0, lo <= q_hip1 <= hi]``, the swing
    tip's height (m) and the stance hip's angle (rad) within its limits; 2 rows, scales
    ``[length, 1]``. (The stance hip is no state of the reduced coordinates.)"""
    stance, swing = reduced_biped(model).legs
    hip_lo, hip_hi = joint_limits(model, stance.hip)

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        q = point(x, u, p).solution.q
        qs = as_scalars(q, model.nq, "q")
        return vector([walking.tip_height(model, q, swing), qs[stance.hip_index]])

    return PathConstraint(SS_GEOMETRY, fn, lower=[0.0, hip_lo], upper=[ca.inf, hip_hi],
                          scale=[model_scale(model).length(LENGTH_SCALE), 1.0])


def clearance_profile_rows(model: RobotModel, options: GaitOptions, point: PointFn
                           ) -> PathConstraint:
    """:data:`CLEARANCE`, single support: ``y_2(q) - profile(s) >= 0`` (m; one row, scale a
    length), the swing tip above :func:`clearance_profile` of height
    ``options.swing_clearance``, ``s = t / T1`` and ``T1 = f L / v`` (single support starts
    the step at ``t = 0``)."""
    assert options.swing_clearance is not None
    swing = reduced_biped(model).swing
    clearance, profile = options.swing_clearance, options.clearance_profile
    fraction = options.single_support_fraction

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        s = t * p[_V] / (fraction * p[_L])
        return walking.tip_height(model, point(x, u, p).solution.q, swing) \
            - clearance_profile(clearance, s, profile)

    return PathConstraint(CLEARANCE, fn, lower=0.0, upper=ca.inf,
                          scale=model_scale(model).length(LENGTH_SCALE))


def double_support_force_rows(model: RobotModel, friction: float | None, point: PointFn
                              ) -> PathConstraint:
    """:data:`DS_FORCES`, double support: ``[f1_y, f2_y] >= 0`` (N), the ground's normal
    forces on tips 1 and 2, then with ``friction = mu`` their cones ``mu f_y -+ f_x >= 0``
    (tip 1's, then tip 2's); 2 or 6 rows, scaled by the weight ``m g`` (N)."""

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        fx1, fy1, fx2, fy2 = as_scalars(point(x, u, p).solution.forces, 4, "forces")
        return vector([fy1, fy2] + friction_rows(friction, fx1, fy1)
                      + friction_rows(friction, fx2, fy2))

    return PathConstraint(DS_FORCES, fn, lower=0.0, upper=ca.inf,
                          scale=model.total_mass * 9.81)


def reach_and_hip_rows(model: RobotModel, options: GaitOptions, point: PointFn
                       ) -> PathConstraint:
    """:data:`DS_GEOMETRY`, double support: ``r_min <= |hip - (L, 0)| <= r_max`` (m, the
    front leg's reach, :func:`leg_reach`) and both hips' angles (rad, stance then swing)
    within their limits; 3 rows, unscaled."""
    stance, swing = reduced_biped(model).legs
    r_min, r_max = leg_reach(model, options)
    hip_lo, hip_hi = joint_limits(model, stance.hip)
    sw_lo, sw_hi = joint_limits(model, swing.hip)

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        qs = as_scalars(point(x, u, p).solution.q, model.nq, "q")
        return vector([walking.front_leg_reach(x, p[_L]), qs[stance.hip_index],
                       qs[swing.hip_index]])

    return PathConstraint(DS_GEOMETRY, fn, lower=[r_min, hip_lo, sw_lo],
                          upper=[r_max, hip_hi, sw_hi])


def single_support_path(model: RobotModel, options: GaitOptions, point: PointFn
                        ) -> list[PathConstraint]:
    """The path constraints of single support, in row order: :func:`stance_force_rows`,
    :func:`swing_clearance_and_hip_rows` and, with a swing clearance,
    :func:`clearance_profile_rows`."""
    path = [stance_force_rows(model, options.friction, point),
            swing_clearance_and_hip_rows(model, point)]
    if options.swing_clearance:  # None or 0: y >= 0 only
        path.append(clearance_profile_rows(model, options, point))
    return path


def double_support_path(model: RobotModel, options: GaitOptions, point: PointFn
                        ) -> list[PathConstraint]:
    """The path constraints of double support, in row order:
    :func:`double_support_force_rows`, :func:`reach_and_hip_rows`."""
    return [double_support_force_rows(model, options.friction, point),
            reach_and_hip_rows(model, options, point)]


def heel_strike_at(model: RobotModel, ends: Mapping[str, Any], p: Any, *,
                   double_support: bool) -> walking.Transition:
    """The heel strike at the end of single support (:func:`walking.heel_strike`)."""
    return walking.heel_strike(model, ends[SINGLE].xf, p[_L], double_support=double_support)


def liftoff_at(model: RobotModel, ends: Mapping[str, Any], p: Any) -> walking.Transition:
    """The liftoff at the end of double support with the impulse ``P``
    (:func:`walking.liftoff`)."""
    return walking.liftoff(model, ends[DOUBLE].xf, p[_L], p[_P])


def landing_rows(model: RobotModel) -> BoundaryConstraint:
    """:data:`LANDING`: ``p_2(q(T1)) - (L, 0) = 0`` (m), tip 2 at the end of single support
    lands one step ahead of tip 1; 2 rows, scale a length."""
    swing = reduced_biped(model).swing

    def fn(ends: Mapping[str, Any], p: Any) -> Any:
        q, _ = walking.single_support_to_full(model, ends[SINGLE].xf)
        c = model.contact(swing.contact)
        tip = as_scalars(point_position(model, q, c.link, model.link(c.link).local_point(*c.at)),
                         2, "tip")
        return vector([tip[0] - p[_L], tip[1]])

    return BoundaryConstraint(LANDING, fn, 0.0, 0.0,
                              scale=model_scale(model).length(LENGTH_SCALE))


def event_friction_rows(model: RobotModel, friction: float, *, double_support: bool
                        ) -> BoundaryConstraint:
    """:data:`EVENT_FRICTION`: ``mu n -+ t >= 0`` for every impulse ``(t, n)`` (N s) of the
    ground on a held tip: the heel strike's (tip 1's if held, then tip 2's) and with
    double support the liftoff's on tip 2; 2 rows per impulse, scale 1."""
    swing = reduced_biped(model).swing

    def fn(ends: Mapping[str, Any], p: Any) -> Any:
        held = list(heel_strike_at(model, ends, p, double_support=double_support)
                    .impulses.values())
        if double_support:
            held.append(liftoff_at(model, ends, p).impulses[swing.contact])
        rows = []
        for impulse in held:
            t_imp, n_imp = as_scalars(impulse, 2, "impulse")
            rows += friction_rows(friction, t_imp, n_imp)
        return vector(rows)

    return BoundaryConstraint(EVENT_FRICTION, fn, lower=0.0, upper=ca.inf, scale=1.0)


def strike_impulse_rows(model: RobotModel, floor: float) -> BoundaryConstraint:
    """:data:`STRIKE_IMPULSES`, with double support: ``[n_1, n_2] >= floor``, the normal
    impulses (N s) of the heel strike on tip 1 (held) and tip 2 (landing); scale 1."""
    stance, swing = reduced_biped(model).legs

    def fn(ends: Mapping[str, Any], p: Any) -> Any:
        imp = heel_strike_at(model, ends, p, double_support=True).impulses
        return vector([as_scalars(imp[stance.contact], 2, "i")[1],
                       as_scalars(imp[swing.contact], 2, "i")[1]])

    return BoundaryConstraint(STRIKE_IMPULSES, fn, lower=floor, upper=ca.inf, scale=1.0)


def departure(model: RobotModel, tr: walking.Transition) -> Any:
    """At the event where tip 1 leaves the ground: ``[n_2, v_1y]``, the normal impulse (N s)
    on tip 2 (which stays) and the vertical velocity (m/s) of tip 1 afterwards (it must
    rise)."""
    stance, swing = reduced_biped(model).legs
    normal = as_scalars(tr.impulses[swing.contact], 2, "i")[1]
    v_up = walking.tip_vertical_velocity(model, tr.q, tr.qd_after, stance)
    return vector([normal, v_up])


def liftoff_rows(model: RobotModel, floor: float) -> BoundaryConstraint:
    """:data:`LIFTOFF_CONDITIONS`, with double support: :func:`departure` at the liftoff,
    ``n_2 >= floor`` and ``v_1y >= 0``; scales ``[1, 0.1]``."""
    return BoundaryConstraint(LIFTOFF_CONDITIONS,
                              lambda ends, p: departure(model, liftoff_at(model, ends, p)),
                              lower=[floor, 0.0], upper=ca.inf, scale=[1.0, 0.1])


def strike_alone_rows(model: RobotModel, floor: float) -> BoundaryConstraint:
    """:data:`STRIKE_ALONE`, without double support: :func:`departure` at the heel strike
    (tip 1 leaves as tip 2 lands), ``n_2 >= floor`` and ``v_1y >= 0``; scales ``[1, 0.1]``."""
    return BoundaryConstraint(
        STRIKE_ALONE,
        lambda ends, p: departure(model, heel_strike_at(model, ends, p, double_support=False)),
        lower=[floor, 0.0], upper=ca.inf, scale=[1.0, 0.1])


def event_constraints(model: RobotModel, options: GaitOptions) -> list[BoundaryConstraint]:
    """The boundary constraints of a step, in row order: :func:`landing_rows`, the
    :func:`step_time_row` when a step time is given, :func:`event_friction_rows` with
    friction, then :func:`strike_impulse_rows` and :func:`liftoff_rows` with double support
    or :func:`strike_alone_rows` without. The normal impulses on held tips are bounded below
    by 0 when ``options.unilateral_impulses`` (else not at all: the paper's maps)."""
    two_phases = options.double_support
    floor = 0.0 if options.unilateral_impulses else -ca.inf
    events = [landing_rows(model)]
    if options.step_time is not None:
        events.append(step_time_row())
    if options.friction is not None:
        events.append(event_friction_rows(model, options.friction, double_support=two_phases))
    if two_phases:
        events += [strike_impulse_rows(model, floor), liftoff_rows(model, floor)]
    else:
        events.append(strike_alone_rows(model, floor))
    return events
