"""The walking problem in full coordinates: the whole tree's ``q, qd`` on a contact sequence.

Beside the paper's reduced formulation (:mod:`gaitopt.gait.formulations.reduced.problem`: polar hip
coordinates and leg inverse kinematics, singular at a straight knee, five-link bipeds only), this
formulation works for any planar tree with contact points and any :class:`ContactSequence`:

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
  stated twice), and ``gamma = nu = 0`` at the first knot. The first pinned point of a
  phase states them by construction instead
  (:mod:`~gaitopt.gait.formulations.full.base_placement`): at those knots the base's ``x, y``
  and their rates are not variables but its position and velocity solved for the base
  (:class:`~gaitopt.ocp.problem.KnotStates`), the same optimum with 4 fewer unknowns and
  rows per knot. This makes the NLP square in the constraint directions: the projection is
  the discrete correction of the collocation's drift (as in Posa, Kuindersma and Tedrake
  2016) and vanishes as the grid is refined. The contact points stay put to the solver's
  tolerance at every knot;
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
  (:func:`~gaitopt.gait.sequence.phase_fractions.fraction_parameters`; its bounds a boundary row
  :data:`~gaitopt.gait.formulations.full.constraints.REMAINDER` when the others' do not imply
  them);
* the paper's objective ``(sum of int u'u dt + P^2) / L`` over the actuator controls only.

The rows relaxed by the first continuation stage are named like the reduced problem's
(:data:`~gaitopt.gait.formulations.full.constraints.FORCES`,
:data:`~gaitopt.gait.formulations.full.constraints.IMPULSES`).

:func:`full_problem` lists the parts of the problem; each is built by a named function, in
one module per concept of the formulation folder:

* here, the phases (:func:`full_phase`: the dynamics of :class:`PointCache`,
  :func:`state_bounds`, :func:`control_bounds`, :func:`running_cost`), the objective's terms
  (:func:`parameter_cost`, :func:`impulse_cost`) and the stages' bounds
  (:func:`full_stage_bounds`);
* :mod:`gaitopt.gait.formulations.full.constraints`: the constraint blocks, one function each
  (the held points, the contact forces and friction cones, the clearances, the touchdowns,
  the impulses, the released points rising, the remainder share);
* :mod:`gaitopt.gait.formulations.full.linkages`: the event maps and the controls' linkages;
* :mod:`gaitopt.gait.formulations.full.parameters`: the parameters and the phase times;
* :mod:`gaitopt.gait.formulations.full.base_placement`: the base placed by a pinned point.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import casadi as ca
import numpy as np

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.kinematics import contact_velocity
from gaitopt.gait.formulations import cost
from gaitopt.gait.formulations.full.base_placement import BASE_STATES, base_point, placed_base
from gaitopt.gait.formulations.full.constraints import (
    CLEARANCE,
    CLEARANCE_PROFILE,
    EVENT_FRICTION,
    FORCES,
    HELD,
    IMPULSES,
    LANDING_CLEARANCE,
    event_rows,
    phase_path,
    remainder_row,
    split_state,
)
from gaitopt.gait.formulations.full.linkages import step_linkages
from gaitopt.gait.formulations.full.parameters import (
    full_parameters,
    period_parameters,
    phase_duration,
)
from gaitopt.gait.formulations.full.physics import (
    PointValues,
    actuator_names,
    event_map,
    full_controls,
    period_map,
    phase_point,
    projection_names,
    state_names,
)
from gaitopt.gait.formulations.step_parameters import IMPULSE_INDEX, step_time_row
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.sequence.contact_sequence import ContactSequence, check_sequence, phase_knots
from gaitopt.ocp.bounds import Bounds
from gaitopt.ocp.problem import Duration, KnotStates, Phase, Problem
from gaitopt.ocp.transcription import Transcription
from gaitopt.robot.biped import BipedStructureError, biped_of
from gaitopt.robot.model import RobotModel

_P = IMPULSE_INDEX
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


def full_problem(model: RobotModel, options: GaitOptions, seq: ContactSequence, *,
                 place_base: bool = True) -> Problem:
    """The OCP of one periodic step of ``seq`` in full coordinates (module docstring): its
    phases, the event maps and control linkages, the events' boundary constraints, the step
    time and remainder rows, the parameters and the objective, in the NLP's order.

    ``place_base`` (default): the first pinned point of each phase places the base at the
    knots after the first (:func:`~gaitopt.gait.formulations.full.base_placement.base_point`)
    instead of its held-point rows; False states those rows (the same optimum, a larger
    NLP)."""
    symmetry = period_map(model, seq)
    check_sequence(model, seq, dict(symmetry.contacts))
    counts = phase_knots(seq, options.knots)
    phases = [full_phase(model, options, seq, i, counts[i], place_base=place_base)
              for i in range(len(seq.phases))]
    events = [row for i in range(len(seq.events))
              for row in event_rows(model, options, seq, symmetry, i)]
    if options.step_time is not None:
        events.append(step_time_row())
    remainder = remainder_row(seq)
    if remainder is not None:
        events.append(remainder)
    return Problem(
        phases=phases, parameters=full_parameters(model, options, seq),
        linkages=step_linkages(model, options, seq, symmetry), boundary_constraints=events,
        parameter_cost=parameter_cost(model, options, seq),
        mayer=None if options.cost == "paper" else impulse_cost(model, options, seq),
        cost_denominator=lambda ends, p: cost.denominator(model, options,
                                                          period_parameters(seq, p)),
        objective_scale=cost.objective_scale(options, model_scale(model)))


class PointCache:
    """A phase's Contact Algorithm (:func:`~gaitopt.gait.formulations.full.physics.phase_point`
    of the hold specs ``held`` and the actuators ``actuators``), evaluated once per symbolic
    point ``(x, u)`` and shared between the dynamics, the contact-force rows and the cost (the
    engine calls each with the same symbols)."""

    def __init__(self, model: RobotModel, held: Sequence[str], actuators: Sequence[str]
                 ) -> None:
        self._model, self._held, self._actuators = model, held, actuators
        self._key: tuple[Any, Any] | None = None
        self._value: PointValues | None = None

    def __call__(self, x: Any, u: Any) -> PointValues:
        key = self._key
        if key is None or key[0] is not x or key[1] is not u:
            self._value = phase_point(self._model, self._held, self._actuators, x, u)
            self._key = (x, u)
        assert self._value is not None
        return self._value

    def dynamics(self, x: Any, u: Any, p: Any, t: Any) -> Any:
        """The phase's ``xdot = [qd + J^T gamma, qdd + J^T nu]`` (``2 nq``) at ``(x, u)``."""
        return self(x, u).xdot


def full_phase(model: RobotModel, options: GaitOptions, seq: ContactSequence, index: int,
               knots: int, *, place_base: bool = True) -> Phase:
    """Phase ``index`` of ``seq`` on ``knots`` knots: the states ``[q, qd]`` within
    :func:`state_bounds`, the controls (its actuators, then the projection controls, 0 at
    the first knot) within :func:`control_bounds`, the dynamics of :class:`PointCache`, the
    duration :func:`~gaitopt.gait.formulations.full.parameters.phase_duration`, the path
    constraints of :func:`~gaitopt.gait.formulations.full.constraints.phase_path`, the
    :func:`running_cost`, and with ``place_base`` the base placed by
    :func:`~gaitopt.gait.formulations.full.base_placement.base_point`."""
    held = seq.phases[index].held
    acts = actuator_names(model, held, ankle=options.ankle)
    proj = projection_names(held)
    controls = acts + proj
    point = PointCache(model, held, acts)
    placed = base_point(model, held) if place_base else None
    return Phase(
        name=seq.phases[index].name, states=state_names(model), controls=controls,
        dynamics=point.dynamics, duration=Duration.of_parameters(phase_duration(seq, index)),
        state_bounds=state_bounds(model, options, held),
        control_bounds=control_bounds(model, acts, proj),
        initial_control={n: 0.0 for n in proj},
        path_constraints=phase_path(model, options, seq, index, point, placed),
        lagrange=running_cost(model, options, seq, acts, len(controls)),
        state_scales=state_scales(model), control_scales={n: PROJECTION_SCALE for n in proj},
        control_rate_weights={a: r for a, r in cost.torque_rate_weights(model, options).items()
                              if a in acts},
        intervals=knots - 1,
        knot_states=None if placed is None else KnotStates(
            BASE_STATES, placed_base(model, seq, placed, index)))


def stance_knees(model: RobotModel) -> dict[str, str]:
    """Contact name -> the knee joint of its leg, for five-link-like models (else empty)."""

    try:
        legs = biped_of(model).legs
    except BipedStructureError:
        return {}
    return {leg.contact: leg.knee for leg in legs}


def state_bounds(model: RobotModel, options: GaitOptions, held: Sequence[str]
                 ) -> dict[str, tuple[float, float]]:
    """The box on ``[q, qd]`` in a phase holding ``held``: the base's ``|x| <= BASE_REACH``
    and ``0 <= y <= BASE_REACH`` (m, times the model's leg length ratio), its angle within
    ``options.torso_bounds`` (rad), the joints within their limits (rad), the knee of a
    held point's leg bent by at least ``options.min_stance_knee_flexion`` (rad), and every
    rate within ``options.rate_bound`` (rad/s; the base position's in m/s, times the leg
    length ratio)."""
    sc = model_scale(model)
    limits = {j.name: j.limits for j in model.joints}
    knees = stance_knees(model)
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
        v = sc.length(options.rate_bound) if n in ("x", "y") else options.rate_bound
        b[f"{n}_rate"] = (-v, v)
    return b


def control_bounds(model: RobotModel, actuators: Sequence[str], projections: Sequence[str]
                   ) -> dict[str, tuple[float, float]]:
    """The torque limits (N m) of ``actuators`` and ``|gamma|, |nu| <= PROJECTION_BOUND`` on
    the projection controls ``projections``."""
    bounds = {a: model.actuators[model.actuator_index(a)].limits for a in actuators}
    return bounds | {n: (-PROJECTION_BOUND, PROJECTION_BOUND) for n in projections}


def state_scales(model: RobotModel) -> dict[str, float]:
    """The states' scales in the NLP: 1 for the coordinates, :data:`RATE_SCALE` for the
    rates."""
    return {n: 1.0 for n in state_names(model)} | {f"{n}_rate": RATE_SCALE
                                                   for n in model.coordinate_names}


def running_cost(model: RobotModel, options: GaitOptions, seq: ContactSequence,
                 actuators: Sequence[str], n_controls: int
                 ) -> Callable[[Any, Any, Any, Any], Any]:
    """The running cost of a phase with ``actuators`` first among its ``n_controls``
    controls, ``(x, u, p, t) ->`` the paper's ``u_a'u_a`` (N^2 m^2, the actuators only) or
    :func:`cost.running_cost` of ``qd`` and the torques over the period
    (:func:`~gaitopt.gait.formulations.full.parameters.period_parameters`)."""
    nq = model.nq

    def fn(x: Any, u: Any, p: Any, t: Any) -> Any:
        n_act = len(actuators)
        if options.cost == "paper" and options.cost_regularization == 0.0:
            return ca.sumsqr(u[:n_act]) if n_act else ca.SX(0.0)
        qd = vector(as_scalars(x, 2 * nq, "x")[nq:])
        u_act = as_scalars(u, n_controls, "u")[:n_act] if n_act else []
        return cost.running_cost(model, options, qd, full_controls(model, actuators, u_act),
                                 period_parameters(seq, p))

    return fn


def parameter_cost(model: RobotModel, options: GaitOptions, seq: ContactSequence
                   ) -> Callable[[Any], Any]:
    """The objective's term in the parameters: the paper's ``steps P^2`` (N^2 s^2, the
    liftoff impulse of each step), or :func:`cost.parameter_cost` over the period."""
    if options.cost == "paper":
        steps = seq.steps
        return lambda p: steps * p[_P] ** 2
    return lambda p: cost.parameter_cost(model, options, period_parameters(seq, p))


def impulse_cost(model: RobotModel, options: GaitOptions, seq: ContactSequence
                 ) -> Callable[..., Any] | None:
    """The Mayer term of the costs of transport, ``(ends, p) ->`` the work of each liftoff
    impulse (:func:`cost.impulse_cost` of the impulse and the released point's velocity
    after it), summed over the events; None when no event has one."""
    events = [i for i, ev in enumerate(seq.events) if ev.impulse]
    if not events:
        return None

    def mayer(ends: Mapping[str, Any], p: Any) -> Any:
        total: Any = 0.0
        for i in events:
            ev = seq.events[i]
            q, qd = split_state(model, ends[seq.phases[i].name].xf)
            jump = event_map(model, seq, i, q, qd, p[_P])
            v_after = contact_velocity(model, q, jump.qd_after, ev.release[0])
            total = total + cost.impulse_cost(model, options, jump.impulses[ev.release[0]],
                                              v_after, p[_P])
        return total

    return mayer


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
