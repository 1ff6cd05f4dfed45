"""The walking problem in full coordinates: the whole tree's ``q, qd`` on a contact sequence.

(One concept, kept whole at about 470 lines: :func:`full_problem` states the whole OCP, every
constraint block beside the others it must agree with; most helpers serve it alone.)

Beside the paper's reduced formulation (:mod:`gaitopt.gait.problem`: polar hip coordinates and
leg inverse kinematics, singular at a straight knee, five-link bipeds only), this formulation
works for any planar tree with contact points and any :class:`ContactSequence`:

* every phase has the states ``x = [q, qd]`` (``2 nq``, named after ``model.coordinate_names``
  and ``<name>_rate``) and the controls: the joint actuators, the contact (ankle) actuators of
  the held points when ankle torques are on, and the *projection controls* below;
* dynamics: the Contact Algorithm with the phase's points held (``qdd`` and the contact forces
  ``f`` from :func:`gaitopt.dynamics.contact.contact_dynamics`), plus the projection::

      q'  = qd  + J(q)^T gamma
      qd' = qdd + J(q)^T nu

  ``gamma, nu`` (one per constraint row: 2 per pinned point, 1 per normal-only hold ``c:y``;
  named ``gamma_<c>_x`` ...) are free controls that only move the state back onto the
  constraint manifold. The held points' positions ``p_c(q) = (a_c L + b_c, 0)`` (only ``y``
  for a normal-only hold) and velocities ``J qd = 0`` are enforced at every knot after the
  first (at the first they follow from the event map and the previous phase, so they are not
  stated twice), and
  ``gamma = nu = 0`` at the first knot. The first pinned point of a phase states them by
  construction instead (:func:`base_point`): at those knots the base's ``x, y`` and their
  rates are not variables but its position and velocity solved for the base
  (:class:`~gaitopt.ocp.problem.KnotStates`), the same optimum with 4 fewer unknowns and
  rows per knot. This makes the NLP square in the constraint
  directions: the projection is the discrete correction of the collocation's drift (as in
  Posa, Kuindersma and Tedrake 2016) and vanishes as the grid is refined. The contact points
  stay put to the solver's tolerance at every knot;
* events: an inelastic impact (:func:`gaitopt.dynamics.impact.impact`) when points touch
  down, the liftoff impulse (:func:`gaitopt.dynamics.impact.liftoff_impulse`) when a point is
  released with one, and after the last event the leg swap and the shift by one step;
* constraints as in the reduced problem where they make sense: torque and joint limits
  (joints may reach them: a knee may straighten fully), normal forces and impulses ``>= 0``,
  optional friction cones, every point that is not held above the ground, released points
  moving up, points touching down at their anchors, controls continuous and periodic;
* phase ``i`` lasts ``s_i L / v`` with ``s_i`` its share of the step: its fraction, or for
  free fractions the parameters ``fraction_<phase>`` after ``L, v, P`` (bounded), the last
  free phase taking the remainder so that the shares sum to 1
  (:func:`~gaitopt.gait.phase_fractions.fraction_parameters`; its bounds a boundary row
  :data:`REMAINDER` when the others' do not imply them);
* the paper's objective ``(sum of int u'u dt + P^2) / L`` over the actuator controls only.

The rows relaxed by the first continuation stage are named like the reduced problem's
(:data:`FORCES`, :data:`IMPULSES`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import casadi as ca
import numpy as np

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.kinematics import contact_position, contact_velocity
from gaitopt.dynamics.tree import hold_name
from gaitopt.gait import cost
from gaitopt.gait.contact_sequence import (
    ContactSequence,
    EventSpec,
    check_sequence,
    phase_knots,
)
from gaitopt.gait.full_physics import (
    PointValues,
    actuator_names,
    event_impulses,
    event_map,
    full_controls,
    hold_axes,
    period_map,
    phase_point,
    projection_names,
    state_names,
    swap_state,
)
from gaitopt.gait.model_scale import model_scale
from gaitopt.gait.options import GaitOptions
from gaitopt.gait.phase_fractions import fraction_parameters, phase_share, remainder_bounds
from gaitopt.gait.problem import LENGTH_SCALE, clearance_profile, parameter_bounds, parameters_of
from gaitopt.ocp.bounds import Bounds
from gaitopt.ocp.problem import (
    BoundaryConstraint,
    ControlLinkage,
    Duration,
    KnotStates,
    Linkage,
    Parameter,
    PathConstraint,
    Phase,
    Problem,
)
from gaitopt.ocp.transcription import Transcription
from gaitopt.robot.biped import BipedStructureError, biped_of
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import LegSwap

STEP_LENGTH, SPEED, IMPULSE = "step_length", "speed", "impulse"
_L, _V, _P, _F = range(4)
#: The floating base's translation (m) and its rates (m/s), placed by a pinned point.
BASE_STATES = ("x", "y", "x_rate", "y_rate")

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
#: The step time ``L / v`` (s) row, present when a step time is given.
STEP_TIME = "step time L / v"
#: The bounds of the free phase that takes the remainder of the step time (suffix of
#: ``<phase>: ...``), when the other free fractions' bounds do not imply them.
REMAINDER = "share within its bounds (the remainder of the step)"
#: Bound (m) of the base position ``|x|`` and ``y`` on the reference biped (1 m legs; times
#: ``l / l_ref`` on another model): generous, a step spans less.
BASE_REACH = 3.0
#: Bound on the projection controls (m/s and m/s^2 per unit of J^T): generous, they vanish.
PROJECTION_BOUND = 10.0
#: Scales of the rate states (rad/s, m/s) and of the projection controls in the NLP. Measured
#: from the naive guess at 12 m/min: with projection controls scaled by 0.01 (their size at
#: the optimum) two of three cold starts did not converge in 500 iterations; scaled by 1,
#: all three converge in 33-47; rate scale 5 made it worse.
RATE_SCALE = 1.0
PROJECTION_SCALE = 1.0


def _limits(model: RobotModel) -> dict[str, tuple[float, float]]:
    return {j.name: j.limits for j in model.joints}


def stance_knees(model: RobotModel) -> dict[str, str]:
    """Contact name -> the knee joint of its leg, for five-link-like models (else empty)."""

    try:
        legs = biped_of(model).legs
    except BipedStructureError:
        return {}
    return {leg.contact: leg.knee for leg in legs}


def base_point(model: RobotModel, held: Sequence[str]) -> str | None:
    """The first point of ``held`` pinned on the ground (``name``, not ``name:y``) if the
    model's first two coordinates ``x, y`` translate the whole tree (then every point's
    position is ``(x, y)`` plus a function of the other coordinates, and its velocity
    ``(x_rate, y_rate)`` plus one of the others: checked at a random state), else None."""
    pinned = [c for c in held if ":" not in c]
    if not pinned or tuple(model.coordinate_names[:2]) != ("x", "y"):
        return None
    nq = model.nq
    q, qd = ca.SX.sym("q", nq), ca.SX.sym("qd", nq)
    qv, qdv = vector(as_scalars(q, nq, "q")), vector(as_scalars(qd, nq, "qd"))
    fn = ca.Function("point", [q, qd], [contact_position(model, qv, pinned[0]),
                                        contact_velocity(model, qv, qdv, pinned[0])])
    rng = np.random.default_rng(0)
    q0, qd0, shift = rng.normal(size=nq), rng.normal(size=nq), np.zeros(nq)
    shift[:2] = rng.normal(size=2)
    p0, v0 = (np.asarray(v).ravel() for v in fn(q0, qd0))
    p1, v1 = (np.asarray(v).ravel() for v in fn(q0 + shift, qd0 + shift))
    translates = np.allclose(p1 - p0, shift[:2], atol=1e-12) and np.allclose(
        v1 - v0, shift[:2], atol=1e-12)
    return pinned[0] if translates else None


def _placed_base(model: RobotModel, seq: ContactSequence, point: str, phase: int
                 ) -> Callable[[Any, Any], Any]:
    """``(x, p) -> (x, y, x_rate, y_rate)`` of the base that puts ``point`` at its ground
    point ``(a L + b, 0)`` of phase ``phase`` at rest: minus its position and velocity with
    the base at 0."""
    nq = model.nq

    def fn(x: Any, p: Any) -> Any:
        xs = as_scalars(x, 2 * nq, "x")
        q = vector([0.0, 0.0] + list(xs[2:nq]))
        qd = vector([0.0, 0.0] + list(xs[nq + 2:]))
        pos = as_scalars(contact_position(model, q, point), 2, "p")
        vel = as_scalars(contact_velocity(model, q, qd, point), 2, "v")
        return vector([seq.ground_x(point, p[_L], phase) - pos[0], -pos[1], -vel[0],
                       -vel[1]])

    return fn


def full_problem(model: RobotModel, options: GaitOptions, seq: ContactSequence, *,
                 place_base: bool = True) -> Problem:
    """The OCP of one periodic step of ``seq`` in full coordinates (module docstring).

    ``place_base`` (default): the first pinned point of each phase places the base at the
    knots after the first (:func:`base_point`) instead of its held-point rows; False states
    those rows (the same optimum, a larger NLP)."""
    symmetry = period_map(model, seq)
    check_sequence(model, seq, dict(symmetry.contacts))
    nq = model.nq
    mu = options.friction
    floor = 0.0 if options.unilateral_impulses else -ca.inf
    limits = _limits(model)
    knees = stance_knees(model)
    names = state_names(model)
    weight = model.total_mass * 9.81
    rate = options.rate_bound
    sc = model_scale(model)
    fractions = fraction_parameters(seq)

    def state_bounds(held: Sequence[str]) -> dict[str, tuple[float, float]]:
        b: dict[str, tuple[float, float]] = {
            "x": (-sc.length(BASE_REACH), sc.length(BASE_REACH)),
            "y": (0.0, sc.length(BASE_REACH)),
            model.base.name: (options.torso_bounds[0], options.torso_bounds[1])}
        for j, lim in limits.items():
            b[j] = lim
        for c in held:
            knee = knees.get(c)
            if knee is not None and options.min_stance_knee_flexion > 0.0:
                lo, hi = limits[knee]
                b[knee] = (lo, min(hi, -options.min_stance_knee_flexion))
        for n in model.coordinate_names:
            # The base position's rates (m/s): the rate bound times the leg length ratio.
            v = sc.length(rate) if n in ("x", "y") else rate
            b[f"{n}_rate"] = (-v, v)
        return b

    phases: list[Phase] = []
    counts = phase_knots(seq, options.knots)
    actuators_of: dict[str, tuple[str, ...]] = {}
    for i_ph, ph in enumerate(seq.phases):
        held = ph.held
        acts = actuator_names(model, held, ankle=options.ankle)
        actuators_of[ph.name] = acts
        proj = projection_names(held)
        controls = acts + proj
        cache: dict[str, Any] = {}

        def point(x: Any, u: Any, held: tuple[str, ...] = held, acts: tuple[str, ...] = acts,
                  cache: dict[str, Any] = cache) -> PointValues:
            key = cache.get("key")
            if key is None or key[0] is not x or key[1] is not u:
                cache["value"] = phase_point(model, held, acts, x, u)
                cache["key"] = (x, u)
            return cache["value"]

        path: list[PathConstraint] = []
        placed = base_point(model, held) if place_base else None
        stated = [(c, a) for c, a in hold_axes(held) if c != placed]
        n_rows = len(stated)
        if stated:
            def held_rows(x: Any, u: Any, p: Any, t: Any,
                          stated: list[tuple[str, int]] = stated, i_ph: int = i_ph) -> Any:
                xs = as_scalars(x, 2 * nq, "x")
                q, qd = vector(xs[:nq]), vector(xs[nq:])
                rows, speeds = [], []
                for c, a in stated:
                    pos = as_scalars(contact_position(model, q, c), 2, "p")
                    vel = as_scalars(contact_velocity(model, q, qd, c), 2, "v")
                    rows.append(pos[a] - seq.ground_x(c, p[_L], i_ph) if a == 0 else pos[a])
                    speeds.append(vel[a])
                return vector(rows + speeds)

            path.append(PathConstraint(HELD, held_rows, lower=0.0, upper=0.0, at="knots",
                                       scale=[sc.length(LENGTH_SCALE)] * n_rows
                                       + [1.0] * n_rows))
        if held:
            def force_rows(x: Any, u: Any, p: Any, t: Any, held: tuple[str, ...] = held,
                           point: Any = point) -> Any:
                f = as_scalars(point(x, u).forces, 2 * len(held), "forces")
                rows = [f[2 * k + 1] for k in range(len(held))]
                if mu is not None:
                    for k, spec in enumerate(held):
                        if ":" not in spec:  # pinned: a friction cone
                            rows += [mu * f[2 * k + 1] - f[2 * k], mu * f[2 * k + 1] + f[2 * k]]
                return vector(rows)

            path.append(PathConstraint(FORCES, force_rows, lower=0.0, upper=ca.inf,
                                       scale=weight))
        landing = seq.events[len(phases)].touchdown
        held_names = [hold_name(c) for c in held]
        free = [c.name for c in model.contacts if c.name not in held_names]
        for label, points in ((CLEARANCE, [c for c in free if c not in landing]),
                              (LANDING_CLEARANCE, [c for c in free if c in landing])):
            if not points:
                continue

            def clearance(x: Any, u: Any, p: Any, t: Any, points: list[str] = points) -> Any:
                q = vector(as_scalars(x, 2 * nq, "x")[:nq])
                return vector([as_scalars(contact_position(model, q, c), 2, "p")[1]
                               for c in points])

            path.append(PathConstraint(label, clearance, lower=0.0, upper=ca.inf,
                                       scale=sc.length(LENGTH_SCALE)))
        if options.swing_clearance is not None and not phases and landing:
            path.append(_clearance_profile(model, options, landing,
                                           _step_share(seq, _share(seq, 0))))

        def dynamics(x: Any, u: Any, p: Any, t: Any, point: Any = point) -> Any:
            return point(x, u).xdot

        def lagrange(x: Any, u: Any, p: Any, t: Any, acts: tuple[str, ...] = acts,
                     n_u: int = len(controls)) -> Any:
            n_act = len(acts)
            if options.cost == "paper" and options.cost_regularization == 0.0:
                return ca.sumsqr(u[:n_act]) if n_act else ca.SX(0.0)
            qd = vector(as_scalars(x, 2 * nq, "x")[nq:])
            u_act = as_scalars(u, n_u, "u")[:n_act] if n_act else []
            return cost.running_cost(model, options, qd, full_controls(model, acts, u_act),
                                     _period(seq, p))

        control_bounds = {a: model.actuators[model.actuator_index(a)].limits for a in acts}
        control_bounds |= {n: (-PROJECTION_BOUND, PROJECTION_BOUND) for n in proj}
        scales = {n: 1.0 for n in names} | {f"{n}_rate": RATE_SCALE
                                            for n in model.coordinate_names}
        phases.append(Phase(
            name=ph.name, states=names, controls=controls, dynamics=dynamics,
            duration=Duration.of_parameters(_step_share(seq, _share(seq, len(phases)))),
            state_bounds=state_bounds(held), control_bounds=control_bounds,
            initial_control={n: 0.0 for n in proj}, path_constraints=path,
            lagrange=lagrange, state_scales=scales,
            control_scales={n: PROJECTION_SCALE for n in proj},
            control_rate_weights={a: r for a, r in cost.torque_rate_weights(
                model, options).items() if a in acts},
            intervals=counts[len(phases)] - 1,
            knot_states=None if placed is None else KnotStates(
                BASE_STATES, _placed_base(model, seq, placed, i_ph))))

    linkages: list[Linkage | ControlLinkage] = []
    events: list[BoundaryConstraint] = []
    n_ph = len(seq.phases)

    def split(x: Any) -> tuple[Any, Any]:
        xs = as_scalars(x, 2 * nq, "x")
        return vector(xs[:nq]), vector(xs[nq:])

    for i, ev in enumerate(seq.events):
        src, dst = seq.phases[i].name, seq.phases[(i + 1) % n_ph].name
        last = i == n_ph - 1

        def jump(xf: Any, uf: Any, p: Any, i: int = i, last: bool = last) -> Any:
            q, qd = split(xf)
            after = event_map(model, seq, i, q, qd, p[_P]).qd_after
            if last:
                q_next, qd_next = swap_state(model, symmetry, q, after, seq.steps * p[_L])
                return vector(q_next + qd_next)
            return vector(as_scalars(q, nq, "q") + as_scalars(after, nq, "qd"))

        period = " (legs swapped)" if seq.steps == 1 else " (a stride: x + 2 L, no swap)"
        linkages.append(Linkage(src, dst, jump=jump, name=f"{ev.name}: event map" +
                                (f" and periodicity{period}" if last else "")))
        if ev.touchdown:
            landing_rows = [(c, a) for c, a in hold_axes(seq.holds_after(i, symmetry.contacts))
                            if c in ev.touchdown]

            def touchdown(ends: Mapping[str, Any], p: Any, src: str = src, i: int = i,
                          landing_rows: list[tuple[str, int]] = landing_rows) -> Any:
                q, _ = split(ends[src].xf)
                rows: list[Any] = []
                for c, a in landing_rows:
                    pos = as_scalars(contact_position(model, q, c), 2, "p")
                    rows.append(pos[a] - seq.ground_x(c, p[_L], i) if a == 0 else pos[a])
                return vector(rows)

            events.append(BoundaryConstraint(f"{ev.name}: {TOUCHDOWN}", touchdown, 0.0, 0.0,
                                             scale=sc.length(LENGTH_SCALE)))
        after = seq.held_after(i)
        if after and (ev.touchdown or ev.impulse):
            def normal(ends: Mapping[str, Any], p: Any, i: int = i, src: str = src,
                       after: tuple[str, ...] = after) -> Any:
                imp = event_impulses(model, seq, i, ends[src].xf, p[_P])
                return vector([as_scalars(imp[c], 2, "i")[1] for c in after])

            events.append(BoundaryConstraint(f"{ev.name}: {IMPULSES}", normal, lower=floor,
                                             upper=ca.inf, scale=1.0))
            pinned = tuple(c for c in seq.holds_after(i, symmetry.contacts) if ":" not in c)
            if mu is not None and pinned:
                def friction(ends: Mapping[str, Any], p: Any, i: int = i, src: str = src,
                             pinned: tuple[str, ...] = pinned) -> Any:
                    imp = event_impulses(model, seq, i, ends[src].xf, p[_P])
                    rows: list[Any] = []
                    for c in pinned:
                        t_i, n_i = as_scalars(imp[c], 2, "i")
                        rows += [mu * n_i - t_i, mu * n_i + t_i]
                    return vector(rows)

                events.append(BoundaryConstraint(f"{ev.name}: {EVENT_FRICTION}", friction,
                                                 lower=0.0, upper=ca.inf, scale=1.0))
        if ev.release and ev.impulse:
            def rise(ends: Mapping[str, Any], p: Any, i: int = i, src: str = src,
                     ev: EventSpec = ev) -> Any:
                q, _ = split(ends[src].xf)
                jump = event_map(model, seq, i, q, vector([0.0] * nq), p[_P]).qd_after
                return vector([as_scalars(contact_velocity(model, q, jump, c), 2, "v")[1]
                               for c in ev.release])

            events.append(BoundaryConstraint(f"{ev.name}: {RISE}", rise, lower=0.0,
                                             upper=ca.inf, scale=0.1))
        if not last and options.control_model == "paper":
            shared = [a for a in actuators_of[src] if a in actuators_of[dst]]
            if shared:
                linkages.append(ControlLinkage(src, dst, controls=shared,
                                               name=f"controls continuous at {ev.name}"))
    if options.periodic_controls and options.control_model == "paper":
        linkages.append(_periodic_controls(model, symmetry, seq, actuators_of))
    if options.step_time is not None:
        events.append(BoundaryConstraint(STEP_TIME, lambda ends, p: p[_L] / p[_V],
                                         lower=-ca.inf, upper=ca.inf, scale=1.0))

    bounds = parameter_bounds(options)
    if not any(ev.impulse for ev in seq.events):
        bounds[IMPULSE] = (0.0, 0.0)
    parameters = parameters_of(bounds, sc)
    parameters += [Parameter(fp.name, fp.lower, fp.upper, scale=1.0, guess=fp.guess)
                   for fp in fractions]
    remainder = remainder_bounds(seq)
    if remainder is not None:
        rest, lo, hi = remainder
        events.append(BoundaryConstraint(f"{seq.phases[rest].name}: {REMAINDER}",
                                         lambda ends, p: _share(seq, rest)(p), lower=lo,
                                         upper=hi, scale=1.0))
    steps = seq.steps
    return Problem(
        phases=phases, parameters=parameters, linkages=linkages, boundary_constraints=events,
        parameter_cost=(lambda p: steps * p[_P] ** 2) if options.cost == "paper" else
        (lambda p: cost.parameter_cost(model, options, _period(seq, p))),
        mayer=None if options.cost == "paper" else _impulse_cost(model, options, seq, split),
        cost_denominator=lambda ends, p: cost.denominator(model, options, _period(seq, p)),
        objective_scale=cost.objective_scale(options, sc))


def _period(seq: ContactSequence, p: Any) -> Any:
    """The parameters ``p`` with the step length ``L`` replaced by the length of the
    period, ``steps L`` (``p`` itself for one step): the costs' denominator and resting
    time are the period's (a stride's cost is per metre of the stride)."""
    if seq.steps == 1:
        return p
    return ca.vertcat(seq.steps * p[_L], p[_V], p[_P])


def _impulse_cost(model: RobotModel, options: GaitOptions, seq: ContactSequence,
                  split: Callable[[Any], tuple[Any, Any]]) -> Callable[..., Any] | None:
    """The Mayer term of the costs of transport: the liftoff impulse's work, if any."""
    events = [i for i, ev in enumerate(seq.events) if ev.impulse]
    if not events:
        return None

    def mayer(ends: Mapping[str, Any], p: Any) -> Any:
        total: Any = 0.0
        for i in events:
            ev = seq.events[i]
            q, qd = split(ends[seq.phases[i].name].xf)
            jump = event_map(model, seq, i, q, qd, p[_P])
            v_after = contact_velocity(model, q, jump.qd_after, ev.release[0])
            total = total + cost.impulse_cost(model, options, jump.impulses[ev.release[0]],
                                              v_after, p[_P])
        return total

    return mayer


def _share(seq: ContactSequence, i: int) -> Callable[[Any], Any]:
    """``p -> `` phase ``i``'s share of the step time (:func:`phase_share`): its fraction,
    or of the free fractions ``p[_F:]`` (in the order of :func:`fraction_parameters`)."""
    n = len(fraction_parameters(seq))
    return lambda p: phase_share(seq, i, [p[_F + k] for k in range(n)])


def _clearance_profile(model: RobotModel, options: GaitOptions, points: Sequence[str],
                       duration: Callable[[Any], Any]) -> PathConstraint:
    """The swing clearance of the first phase (:func:`gaitopt.gait.problem.clearance_profile`):
    each point landing at its end stays above ``profile(s)``, ``s = t / T_0`` (``T_0 =
    duration(p)``, the phase's duration ``f steps L / v``)."""

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


def _step_share(seq: ContactSequence, share: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """``p -> share(p) steps L / v``: a phase's duration (its share of the period: the
    step, or the stride of ``seq.steps = 2`` steps)."""
    steps = seq.steps
    return lambda p: share(p) * steps * p[_L] / p[_V]


def _periodic_controls(model: RobotModel, symmetry: LegSwap, seq: ContactSequence,
                       actuators_of: Mapping[str, Sequence[str]]) -> ControlLinkage:
    """``u_first(0)[a] = (S_u u_last(T))[a] = sign_a u_last(T)[swap(a)]`` for every
    actuator ``a`` of the first phase whose swapped counterpart acts at the end of the last
    phase (``S_u`` a signed permutation: :meth:`LegSwap.actuator_source`; the identity for a
    stride)."""
    first, last = seq.phases[0].name, seq.phases[-1].name
    last_acts = list(actuators_of[last])
    names = [a.name for a in model.actuators]
    targets, sources = [], []
    for a in actuators_of[first]:
        j, sign = symmetry.actuator_source(model.actuator_index(a))
        if names[j] in last_acts:
            targets.append(a)
            sources.append((last_acts.index(names[j]), sign))
    n_last = len(last_acts) + 2 * len(hold_axes(seq.phases[-1].held))

    def fn(u_from: Any, p: Any) -> Any:
        us = as_scalars(u_from, n_last, "u")
        return vector([us[k] if sign > 0 else -us[k] for k, sign in sources])

    return ControlLinkage(last, first, fn=fn, controls=targets,
                          name="controls periodic (legs swapped)")


def full_stage_bounds(tr: Transcription, force: float, impulse: float) -> Bounds:
    """The transcription's bounds with the held-point rows of each phase's first knot freed
    (they follow from the event maps), and the unilateral conditions relaxed by ``force``
    (N) and ``impulse`` (N s) (0 enforces them)."""
    bounds = tr.bounds()
    for ph, pf in zip(tr.problem.phases, tr.phase_functions, strict=True):
        rows_of = {pr.name: pr for pr in pf.path_rows}
        block = tr.nlp.constraints.block(f"{ph.name}/path@knots")
        if HELD in rows_of:
            pr = rows_of[HELD]
            first = np.arange(pr.rows.start, pr.rows.stop) + block.rows.start
            bounds = bounds.with_rows(first, -ca.inf, ca.inf)
        # Heights at the first knot repeat the previous phase's last knot (events keep q);
        # landing points are on the ground at the last knot by the touchdown constraint.
        last = block.shape[0] - 1
        for label, knots in ((CLEARANCE, (0,)), (LANDING_CLEARANCE, (0, last)),
                             (CLEARANCE_PROFILE, (0, last))):
            if label in rows_of:
                pr = rows_of[label]
                for k in knots:
                    rows = block.rows.start + k * pf.n_path + np.arange(pr.rows.start,
                                                                        pr.rows.stop)
                    bounds = bounds.with_rows(rows, -ca.inf, ca.inf)
        if FORCES in rows_of and force > 0.0:
            rows = tr.path_rows(ph.name, FORCES)
            bounds = bounds.with_rows(rows, np.minimum(bounds.lbg[rows], -force), ca.inf)
    if impulse > 0.0:
        for blk in tr.nlp.constraints.blocks:
            if blk.name.endswith(IMPULSES) or blk.name.endswith(EVENT_FRICTION):
                rows = np.arange(blk.rows.start, blk.rows.stop)
                bounds = bounds.with_rows(rows, np.minimum(bounds.lbg[rows], -impulse),
                                          ca.inf)
    return bounds
