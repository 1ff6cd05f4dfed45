"""The constraint blocks of the full formulation's walking problem, one named builder each.

:func:`gaitopt.gait.formulations.full.problem.full_problem` assembles them: the path
constraints of each phase (:func:`phase_path`) and the boundary constraints of each event
(:func:`event_rows`), then the step time and the remainder share, in that order, which is
the order of the NLP's rows. The names of the blocks (:data:`HELD`, :data:`FORCES`, ...) are
what the stages relax and free
(:func:`~gaitopt.gait.formulations.full.problem.full_stage_bounds`).

Conventions of every builder: the world frame has ``x`` forward along the ground and ``y``
up, the ground at ``y = 0``; a held point ``c`` of phase ``i`` stands at its ground point
``(a_c L + b_c, 0)`` (:meth:`ContactSequence.ground_x`). Lengths are in m, velocities in
m/s, forces in N (the ground's force on a point, world ``(x, y)``), impulses in N s.
``x = [q, qd]`` is a phase's state (``2 nq``), ``u`` its controls (the actuator torques,
then the projection controls), ``p = [L, v, P, fractions ...]`` the parameters
(:mod:`gaitopt.gait.formulations.full.parameters`), ``t`` the time (s) from the start of
the phase. A path constraint's function takes ``(x, u, p, t)``; a phase's ``point`` takes
``(x, u)`` and returns the Contact Algorithm's values there
(:class:`~gaitopt.gait.formulations.full.physics.PointValues`, computed once per point and
shared with the dynamics). A boundary constraint's function takes ``(ends, p)``,
``ends[phase].xf`` the state at a phase's end; event ``i`` ends phase ``i``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import casadi as ca

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.kinematics import contact_position, contact_velocity
from gaitopt.dynamics.tree import hold_name
from gaitopt.gait.formulations.full.parameters import phase_duration, share_of
from gaitopt.gait.formulations.full.physics import (
    PointValues,
    event_impulses,
    event_map,
    hold_axes,
)
from gaitopt.gait.formulations.shared_rows import LENGTH_SCALE, clearance_profile, friction_rows
from gaitopt.gait.formulations.step_parameters import IMPULSE_INDEX, STEP_LENGTH_INDEX
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.sequence.contact_sequence import ContactSequence
from gaitopt.gait.sequence.phase_fractions import remainder_bounds
from gaitopt.ocp.problem import BoundaryConstraint, PathConstraint
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import LegSwap

_L, _P = STEP_LENGTH_INDEX, IMPULSE_INDEX

#: Path constraint of the held points' positions and velocities (knots only).
HELD = "held points: position and velocity"
#: Path constraint of the normal contact forces (and friction cones).
FORCES = "contact forces"
#: Path constraint of the points not held: heights >= 0.
CLEARANCE = "free points above the ground"
#: The same for the points that touch down at the end of the phase (not at its last knot,
#: where the touchdown constraint puts them on the ground).
LANDING_CLEARANCE = "landing points above the ground"
#: The optional swing clearance profile of the first phase (the reduced problem's name).
CLEARANCE_PROFILE = "swing clearance profile"
#: Boundary constraints of the events (suffixes of ``<event>: ...``).
TOUCHDOWN = "touchdown at the anchor"
IMPULSES = "normal impulses"
RISE = "released points rise (impulse)"
EVENT_FRICTION = "friction cones of the impulses"
#: The bounds of the free phase that takes the remainder of the step time (suffix of
#: ``<phase>: ...``), when the other free fractions' bounds do not imply them.
REMAINDER = "share within its bounds (the remainder of the step)"

#: A phase's Contact Algorithm at one point, ``(x, u) -> PointValues``.
PointFn = Callable[[Any, Any], PointValues]


def split_state(model: RobotModel, x: Any) -> tuple[Any, Any]:
    """``(q, qd)``, each ``(nq,)`` (rad or m; rad/s or m/s), of the state ``x = [q, qd]``."""
    nq = model.nq
    xs = as_scalars(x, 2 * nq, "x")
    return vector(xs[:nq]), vector(xs[nq:])


def ground_offsets(model: RobotModel, seq: ContactSequence, phase: int, q: Any,
                   axes: Sequence[tuple[str, int]], step_length: Any) -> list[Any]:
    """For each ``(c, axis)`` of ``axes``: ``x_c(q) - (a_c L + b_c)`` along x (axis 0), or
    ``y_c(q)`` along y (axis 1), the point's offset (m) from its ground point in phase
    ``phase``."""
    rows: list[Any] = []
    for c, a in axes:
        pos = as_scalars(contact_position(model, q, c), 2, "p")
        rows.append(pos[a] - seq.ground_x(c, step_length, phase) if a == 0 else pos[a])
    return rows


def held_point_rows(model: RobotModel, seq: ContactSequence, phase: int,
                    stated: Sequence[tuple[str, int]]) -> PathConstraint:
    """:data:`HELD`, at the knots of phase ``phase``: for the hold rows ``stated`` (``(c,
    axis)``, :func:`~gaitopt.gait.formulations.full.physics.hold_axes`), the positions
    ``p_c(q)[axis] - ground = 0`` (m, :func:`ground_offsets`) then the velocities
    ``(J_c(q) qd)[axis] = 0`` (m/s); ``2 len(stated)`` rows, scaled by a length then 1.
    (The stages free them at the first knot, where the event map states them.)"""
    n_rows = len(stated)

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        q, qd = split_state(model, x)
        speeds = [as_scalars(contact_velocity(model, q, qd, c), 2, "v")[a] for c, a in stated]
        return vector(ground_offsets(model, seq, phase, q, stated, p[_L]) + speeds)

    return PathConstraint(HELD, fn, lower=0.0, upper=0.0, at="knots",
                          scale=[model_scale(model).length(LENGTH_SCALE)] * n_rows
                          + [1.0] * n_rows)


def contact_force_rows(model: RobotModel, held: Sequence[str], friction: float | None,
                       point: PointFn) -> PathConstraint:
    """:data:`FORCES`: ``f_y >= 0`` (N) for the ground's force ``(f_x, f_y)`` on each held
    point (``held``: hold specs, ``c`` pinned or ``c:y`` along the normal), then with
    ``friction = mu`` the cone ``mu f_y -+ f_x >= 0`` of each pinned point; ``len(held)``
    rows plus 2 per pinned point, scaled by the model's weight ``m g`` (N)."""

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        f = as_scalars(point(x, u).forces, 2 * len(held), "forces")
        rows = [f[2 * k + 1] for k in range(len(held))]
        if friction is not None:
            for k, spec in enumerate(held):
                if ":" not in spec:  # pinned: a friction cone
                    rows += friction_rows(friction, f[2 * k], f[2 * k + 1])
        return vector(rows)

    return PathConstraint(FORCES, fn, lower=0.0, upper=ca.inf, scale=model.total_mass * 9.81)


def height_rows(model: RobotModel, name: str, points: Sequence[str]) -> PathConstraint:
    """``name`` (:data:`CLEARANCE` or :data:`LANDING_CLEARANCE`): ``y_c(q) >= 0`` (m), each
    of ``points`` above the ground; one row per point, scale a length."""
    nq = model.nq

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        q = vector(as_scalars(x, 2 * nq, "x")[:nq])
        return vector([as_scalars(contact_position(model, q, c), 2, "p")[1] for c in points])

    return PathConstraint(name, fn, lower=0.0, upper=ca.inf,
                          scale=model_scale(model).length(LENGTH_SCALE))


def clearance_profile_rows(model: RobotModel, options: GaitOptions, points: Sequence[str],
                           duration: Callable[[Any], Any]) -> PathConstraint:
    """:data:`CLEARANCE_PROFILE`, the swing clearance of the first phase: ``y_c(q) -
    profile(s) >= 0`` (m) for each of ``points`` (the swing foot's, :func:`phase_path`),
    ``profile`` the reduced problem's
    (:func:`~gaitopt.gait.formulations.reduced.constraints.clearance_profile`, of height
    ``options.swing_clearance``) and ``s = t / T_0``, ``T_0 = duration(p)`` the phase's
    duration ``f steps L / v`` (s); one row per point, scale a length."""
    assert options.swing_clearance is not None
    height = options.swing_clearance
    nq = model.nq

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        q = vector(as_scalars(x, 2 * nq, "x")[:nq])
        s = t / duration(p)
        low = clearance_profile(height, s, options.clearance_profile)
        return vector([as_scalars(contact_position(model, q, c), 2, "p")[1] - low
                       for c in points])

    return PathConstraint(CLEARANCE_PROFILE, fn, lower=0.0, upper=ca.inf,
                          scale=model_scale(model).length(LENGTH_SCALE))


def free_points(model: RobotModel, held: Sequence[str]) -> list[str]:
    """The model's contact points that the hold specs ``held`` leave free, in model order."""
    held_names = [hold_name(c) for c in held]
    return [c.name for c in model.contacts if c.name not in held_names]


def phase_path(model: RobotModel, options: GaitOptions, seq: ContactSequence, phase: int,
               point: PointFn, placed: str | None) -> list[PathConstraint]:
    """The path constraints of phase ``phase``, in row order: :func:`held_point_rows` of the
    hold rows not stated by the point ``placed`` (which places the base instead,
    :func:`~gaitopt.gait.formulations.full.base_placement.base_point`), if any;
    :func:`contact_force_rows` if a point is held; :func:`height_rows` of the free points
    (:data:`CLEARANCE`), then of those landing at the phase's end
    (:data:`LANDING_CLEARANCE`), where there are any; and in the first phase, with a swing
    clearance, :func:`clearance_profile_rows` of the points landing at its end or, in a step
    of two phases where none does (a run's stance, whose swing foot lands after the flight),
    of its free points that land at the step's end (a longer step's first phase without a
    landing has none)."""
    held = seq.phases[phase].held
    path: list[PathConstraint] = []
    stated = [(c, a) for c, a in hold_axes(held) if c != placed]
    if stated:
        path.append(held_point_rows(model, seq, phase, stated))
    if held:
        path.append(contact_force_rows(model, held, options.friction, point))
    landing = seq.events[phase].touchdown
    free = free_points(model, held)
    for name, points in ((CLEARANCE, [c for c in free if c not in landing]),
                         (LANDING_CLEARANCE, [c for c in free if c in landing])):
        if points:
            path.append(height_rows(model, name, points))
    if options.swing_clearance and phase == 0:  # None or 0: y >= 0 only
        swinging = landing or (tuple(c for c in seq.events[-1].touchdown if c in free)
                               if len(seq.phases) == 2 else ())
        if swinging:
            path.append(clearance_profile_rows(model, options, swinging,
                                               phase_duration(seq, 0)))
    return path


def touchdown_rows(model: RobotModel, seq: ContactSequence, symmetry: LegSwap, event: int
                   ) -> BoundaryConstraint:
    """``<event>: ``:data:`TOUCHDOWN`: each point touching down at event ``event`` at its
    ground point at the end of the phase before, ``p_c(q)[axis] - ground = 0`` (m,
    :func:`ground_offsets`) along the axes it is held on afterwards
    (:meth:`ContactSequence.holds_after`); one row per axis, scale a length."""
    ev = seq.events[event]
    src = seq.phases[event].name
    axes = [(c, a) for c, a in hold_axes(seq.holds_after(event, symmetry.contacts))
            if c in ev.touchdown]

    def fn(ends: Mapping[str, Any], p: Any) -> Any:
        q, _ = split_state(model, ends[src].xf)
        return vector(ground_offsets(model, seq, event, q, axes, p[_L]))

    return BoundaryConstraint(f"{ev.name}: {TOUCHDOWN}", fn, 0.0, 0.0,
                              scale=model_scale(model).length(LENGTH_SCALE))


def normal_impulse_rows(model: RobotModel, seq: ContactSequence, event: int, floor: float
                        ) -> BoundaryConstraint:
    """``<event>: ``:data:`IMPULSES`: ``n_c >= floor`` (N s), the normal impulse of event
    ``event`` (:func:`~gaitopt.gait.formulations.full.physics.event_impulses`) on each point
    held just after it (:meth:`ContactSequence.held_after`); one row per point, scale 1."""
    ev, src, after = seq.events[event], seq.phases[event].name, seq.held_after(event)

    def fn(ends: Mapping[str, Any], p: Any) -> Any:
        imp = event_impulses(model, seq, event, ends[src].xf, p[_P])
        return vector([as_scalars(imp[c], 2, "i")[1] for c in after])

    return BoundaryConstraint(f"{ev.name}: {IMPULSES}", fn, lower=floor, upper=ca.inf,
                              scale=1.0)


def impulse_friction_rows(model: RobotModel, seq: ContactSequence, event: int,
                          pinned: Sequence[str], friction: float) -> BoundaryConstraint:
    """``<event>: ``:data:`EVENT_FRICTION`: ``mu n -+ t >= 0`` for the impulse ``(t, n)``
    (N s) of event ``event`` on each point of ``pinned`` (held along x and y after it); 2
    rows per point, scale 1."""
    ev, src = seq.events[event], seq.phases[event].name

    def fn(ends: Mapping[str, Any], p: Any) -> Any:
        imp = event_impulses(model, seq, event, ends[src].xf, p[_P])
        rows: list[Any] = []
        for c in pinned:
            t_i, n_i = as_scalars(imp[c], 2, "i")
            rows += friction_rows(friction, t_i, n_i)
        return vector(rows)

    return BoundaryConstraint(f"{ev.name}: {EVENT_FRICTION}", fn, lower=0.0, upper=ca.inf,
                              scale=1.0)


def release_rise_rows(model: RobotModel, seq: ContactSequence, event: int
                      ) -> BoundaryConstraint:
    """``<event>: ``:data:`RISE`: ``(J_c(q) dqd)_y >= 0`` (m/s) for each point ``c``
    released with the liftoff impulse at event ``event``, ``dqd`` the velocity jump of the
    event map from rest (the impulse's own velocity change): the impulse lifts the point;
    one row per point, scale 0.1 m/s."""
    ev, src, nq = seq.events[event], seq.phases[event].name, model.nq

    def fn(ends: Mapping[str, Any], p: Any) -> Any:
        q, _ = split_state(model, ends[src].xf)
        jump = event_map(model, seq, event, q, vector([0.0] * nq), p[_P]).qd_after
        return vector([as_scalars(contact_velocity(model, q, jump, c), 2, "v")[1]
                       for c in ev.release])

    return BoundaryConstraint(f"{ev.name}: {RISE}", fn, lower=0.0, upper=ca.inf, scale=0.1)


def event_rows(model: RobotModel, options: GaitOptions, seq: ContactSequence,
               symmetry: LegSwap, event: int) -> list[BoundaryConstraint]:
    """The boundary constraints of event ``event``, in row order: :func:`touchdown_rows` if
    points touch down; if points are held after it and it is an impact or an impulse,
    :func:`normal_impulse_rows` (bounded below by 0 when ``options.unilateral_impulses``,
    else not at all) and with friction :func:`impulse_friction_rows` of the pinned points;
    :func:`release_rise_rows` if it releases a point with the liftoff impulse."""
    ev = seq.events[event]
    rows: list[BoundaryConstraint] = []
    if ev.touchdown:
        rows.append(touchdown_rows(model, seq, symmetry, event))
    if seq.held_after(event) and (ev.touchdown or ev.impulse):
        floor = 0.0 if options.unilateral_impulses else -ca.inf
        rows.append(normal_impulse_rows(model, seq, event, floor))
        pinned = tuple(c for c in seq.holds_after(event, symmetry.contacts) if ":" not in c)
        if options.friction is not None and pinned:
            rows.append(impulse_friction_rows(model, seq, event, pinned, options.friction))
    if ev.release and ev.impulse:
        rows.append(release_rise_rows(model, seq, event))
    return rows


def remainder_row(seq: ContactSequence) -> BoundaryConstraint | None:
    """``<phase>: ``:data:`REMAINDER`: ``lo <= s_r <= hi``, the share (1) of the free phase
    that takes the remainder of the period within its bounds
    (:func:`~gaitopt.gait.sequence.phase_fractions.remainder_bounds`), one row, scale 1; or
    None when there is none or the other free fractions' bounds imply them."""
    remainder = remainder_bounds(seq)
    if remainder is None:
        return None
    rest, lo, hi = remainder
    share = share_of(seq, rest)
    return BoundaryConstraint(f"{seq.phases[rest].name}: {REMAINDER}",
                              lambda ends, p: share(p), lower=lo, upper=hi, scale=1.0)
