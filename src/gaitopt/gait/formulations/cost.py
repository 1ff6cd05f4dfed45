"""The cost of a step: the paper's, the mechanical cost of transport, or a metabolic-like cost.

Notation: step length ``L`` (m), speed ``v`` (m/s), step time ``T = L / v`` (s), body mass
``m`` (kg), weight ``W = m |g|`` (N), actuator torques ``u_a`` (N m) and their angular rates
``w_a`` (rad/s): a joint actuator's joint rate; a contact (ankle) actuator's link rate, the
absolute angular velocity of the link carrying its point (the ground does not move). The
actuator power is ``p_a = u_a w_a`` (W). ``P`` is the liftoff impulse (N s) and
``E_P = P e . v_tip+ / 2`` the work it does (J; the tip is at rest before it).

* ``paper`` (default, the paper's eq. 5): ``J = (int u'u dt + P^2) / L``, in N^2 m s;
* ``work``: the mechanical cost of transport, positive actuator work per weight and distance,
  ``J = (int sum_a pos(p_a) dt + pos(E_P)) / (W L)``, dimensionless;
* ``metabolic``: positive and negative work with separate efficiencies and a resting power,
  ``J = (int sum_a [pos(p_a) / eta_pos + pos(-p_a) / eta_neg] dt + pos(E_P) / eta_pos +
  P_rest m T) / (W L)``, dimensionless. Defaults: ``eta_pos = 0.25`` and ``eta_neg = 1.2``
  (muscle efficiencies of positive and negative work, Margaria 1968; negative work costs
  1/1.2 of its magnitude), ``P_rest = 1.2`` W/kg (a resting metabolic rate of adults, the
  role it plays in Srinivasan 2009).

``pos(x) = (x + sqrt(x^2 + eps^2)) / 2`` is a smooth ``max(0, x)`` (IPOPT needs derivatives):
``0 <= pos(x) - max(0, x) <= eps / 2``, so with ``eps = cost_smoothing`` (W) the smoothed work
cost exceeds the exact one by at most ``n_a eps T / (2 W L)`` (``n_a`` actuators). An optional
regularisation adds ``r int sum_a (u_a / u_max_a)^2 dt / T`` (dimensionless) to any cost,
and a torque-rate term with time ``tau`` (``torque_rate_time``) adds ``tau^2 int sum_a u_a'^2
dt`` to the paper cost's numerator (``tau^2 W sqrt(g l) int sum_a (u_a' / u_max_a)^2 dt``,
J, to a cost of transport's; ``l`` the leg length): :func:`torque_rate_weights`.
Everything here runs on numbers and CasADi symbols alike.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gaitopt.dynamics.backend import Scalar, as_scalars, sqrt
from gaitopt.dynamics.kinematics import contact_velocity
from gaitopt.dynamics.reduced import double_support_state
from gaitopt.gait.formulations.reduced import physics as walking
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import REFERENCE, ModelScale, model_scale
from gaitopt.gait.record.interpolation import phase_states_at
from gaitopt.gait.sequence.contact_sequence import sequence_from_dict
from gaitopt.robot.model import RobotModel

if TYPE_CHECKING:
    from gaitopt.gait.record.file import Gait
    from gaitopt.gait.record.parts import GaitEvent

COSTS: tuple[str, ...] = ("paper", "work", "metabolic")


@dataclass(frozen=True)
class CostTraits:
    """What a cost declares about itself, as data (the staged solve reads this, never the
    cost's name).

    Attributes:
        name: ``GaitOptions.cost``'s value for it.
        smooth: its integrand is smooth in the NLP's variables (``u'u``). False where it
            takes positive parts of actuator powers, ``max(0, u_a w_a)``, which the NLP
            smooths with ``cost_smoothing`` (:func:`smooth_positive`): such a cost is reached
            from the paper's optimum through coarser smoothings
            (:mod:`gaitopt.gait.solve.cost_continuation`).
    """

    name: str
    smooth: bool


#: Every cost's traits by name (:data:`COSTS`).
COST_TRAITS: dict[str, CostTraits] = {
    "paper": CostTraits("paper", smooth=True),
    "work": CostTraits("work", smooth=False),
    "metabolic": CostTraits("metabolic", smooth=False),
}

FORMULAS = {
    "paper": ("energy per metre (paper eq. 5): (integral over the step of u'u dt + "
              "liftoff_impulse^2) / step_length, in N^2 m s (torques in N m, impulse in N s)"),
    "work": ("mechanical cost of transport: (integral of the positive actuator power + "
             "positive work of the liftoff impulse) / (body weight x step length), "
             "dimensionless; positive parts smoothed with eps = cost_smoothing (W)"),
    "metabolic": ("metabolic cost of transport: (integral of positive power / eta_pos + "
                  "negative power / eta_neg + liftoff impulse work / eta_pos + resting power "
                  "x mass x step time) / (body weight x step length), dimensionless"),
}


def formula(options: GaitOptions) -> str:
    """The cost in words for the gait file (with its settings)."""
    text = FORMULAS[options.cost]
    if options.cost == "metabolic":
        text += (f" (eta_pos = {options.efficiency_positive:g}, eta_neg = "
                 f"{options.efficiency_negative:g}, resting power "
                 f"{options.resting_power:g} W/kg)")
    if options.cost_regularization > 0.0:
        text += (f"; plus {options.cost_regularization:g} x integral of sum (u / u_max)^2 dt "
                 "/ step time")
    if options.torque_rate_time > 0.0:
        tau = options.torque_rate_time
        text += (f"; plus ({tau:g} s)^2 x integral of sum u'^2 dt in the numerator"
                 if options.cost == "paper" else
                 f"; plus ({tau:g} s)^2 x W sqrt(g l) x integral of sum (u' / u_max)^2 dt in "
                 "the numerator")
    return text


def torque_rate_weights(model: RobotModel, options: GaitOptions) -> dict[str, float]:
    """The weight ``r_a`` of each actuator's ``int u_a'^2 dt`` in the cost's numerator
    (:attr:`gaitopt.ocp.problem.Phase.control_rate_weights`): ``tau^2`` (s^2) for the paper
    cost, ``tau^2 W sqrt(g l) / u_max_a^2`` (J s / (N m)^2) for the costs of transport, with
    ``tau = options.torque_rate_time``, ``W`` the body weight, ``l`` the leg length
    (:func:`gaitopt.gait.options.model_scale.model_scale`); empty when ``tau = 0``."""
    tau = options.torque_rate_time
    if tau <= 0.0:
        return {}
    if options.cost == "paper":
        return {a.name: tau * tau for a in model.actuators}
    scale = model_scale(model)
    power = weight(model) * (scale.gravity * scale.leg_length) ** 0.5
    return {a.name: tau * tau * power / (max(abs(a.limits[0]), abs(a.limits[1])) or 1.0) ** 2
            for a in model.actuators}


def torque_rate_cost(model: RobotModel, options: GaitOptions, t: Any, u: Any) -> float:
    """``sum_a r_a sum_k (u[k+1, a] - u[k, a])^2 / (t[k+1] - t[k])``: the exact
    :func:`torque_rate_weights` term of one phase's piecewise-linear torques ``u`` (K, n_a;
    N m) at knot times ``t`` (K,; s); 0 without weights."""
    weights = torque_rate_weights(model, options)
    if not weights or len(t) < 2:
        return 0.0
    r = np.array([weights[a.name] for a in model.actuators])
    du = np.diff(np.asarray(u, dtype=float), axis=0)
    return float(np.sum((du * du) @ r / np.diff(np.asarray(t, dtype=float))))


def smooth_positive(x: Scalar, eps: float) -> Scalar:
    """``(x + sqrt(x^2 + eps^2)) / 2``: within ``[0, eps / 2]`` above ``max(0, x)``."""
    return 0.5 * (x + sqrt(x * x + eps * eps))


def actuator_rates(model: RobotModel, qd: Any) -> list[Scalar]:
    """Angular rates ``w_a`` (rad/s) of every actuator (see the module docstring)."""
    qds = as_scalars(qd, model.nq, "qd")
    out: list[Scalar] = []
    for a in model.actuators:
        if a.joint is not None:
            out.append(qds[model.joint_coordinate(a.joint)])
        else:
            link = model.link_index(model.contact(a.contact or "").link)
            rate: Scalar = 0.0
            for i in model.chain(link):
                rate = rate + qds[model.coordinate_of_link(i)]
            out.append(rate)
    return out


def weight(model: RobotModel) -> float:
    """Body weight ``m |g|`` (N)."""
    gx, gy = model.gravity
    return model.total_mass * float((gx * gx + gy * gy) ** 0.5)


def running_cost(model: RobotModel, options: GaitOptions, qd: Any, u_full: Sequence[Scalar],
                 p: Any) -> Scalar:
    """The integrand of the cost's numerator (before division by the denominator); ``p``
    starts with ``[L, v]`` (numbers or symbols)."""
    us = list(u_full)
    total: Scalar = 0.0
    if options.cost == "paper":
        for u in us:
            total = total + u * u
    else:
        eps = options.cost_smoothing
        for u, w in zip(us, actuator_rates(model, qd), strict=True):
            power = u * w
            total = total + smooth_positive(power, eps) / (
                1.0 if options.cost == "work" else options.efficiency_positive)
            if options.cost == "metabolic":
                total = total + smooth_positive(-power, eps) / options.efficiency_negative
    if options.cost_regularization > 0.0:
        step_time = p[0] / p[1]
        norm: Scalar = 0.0
        for u, a in zip(us, model.actuators, strict=True):
            u_max = max(abs(a.limits[0]), abs(a.limits[1])) or 1.0
            norm = norm + (u / u_max) ** 2
        total = total + options.cost_regularization * norm / step_time * denominator(
            model, options, p)
    return total


def impulse_cost(model: RobotModel, options: GaitOptions, impulse_vector: Any,
                 v_tip_after: Any, magnitude: Scalar) -> Scalar:
    """The cost's numerator term of the liftoff impulse: ``P^2`` (paper), or its positive
    work ``E_P = P e . v_tip+ / 2`` (J; over ``eta_pos`` for the metabolic cost)."""
    if options.cost == "paper":
        return magnitude * magnitude
    imp = as_scalars(impulse_vector, 2, "impulse")
    v = as_scalars(v_tip_after, 2, "v")
    # No smoothing needed: with the tip at rest before, E_P is the kinetic energy the impulse
    # adds (the held points, at rest before and after, take no work), never negative.
    work = 0.5 * (imp[0] * v[0] + imp[1] * v[1])
    return work if options.cost == "work" else work / options.efficiency_positive


def parameter_cost(model: RobotModel, options: GaitOptions, p: Any) -> Scalar:
    """The numerator term of the parameters: the resting energy ``P_rest m T`` (J) of the
    metabolic cost, else 0."""
    if options.cost != "metabolic":
        return 0.0
    return options.resting_power * model.total_mass * p[0] / p[1]


def denominator(model: RobotModel, options: GaitOptions, p: Any) -> Scalar:
    """``L`` (paper) or ``W L`` (the costs of transport)."""
    step = p[0]
    return step if options.cost == "paper" else weight(model) * step


#: The objective scales on the reference biped (the five-link's 1 m legs, 42 kg): the paper's
#: cost (N^2 m s) and the costs of transport (dimensionless, the same on every model).
PAPER_OBJECTIVE_SCALE, TRANSPORT_OBJECTIVE_SCALE = 1000.0, 0.1


def objective_scale(options: GaitOptions, scale: ModelScale = REFERENCE) -> float:
    """The NLP minimises ``J / objective_scale``: about the size of the optimum
    (:data:`PAPER_OBJECTIVE_SCALE` carried over to the model of ``scale`` as a paper cost,
    ``(m g l)^2 sqrt(l / g) / l``; :data:`TRANSPORT_OBJECTIVE_SCALE` for the costs of
    transport)."""
    if options.cost == "paper":
        return scale.paper_cost(PAPER_OBJECTIVE_SCALE)
    return TRANSPORT_OBJECTIVE_SCALE


def recompute_cost(gait: Any) -> float:
    """The cost of a saved gait from its file alone, as the transcription defines it:
    Simpson's rule per interval on the knots and the interval midpoints (states from the
    phase's cubic Hermite interpolant, controls linear), plus the impulse and resting terms,
    over the denominator. For the paper's cost this is the exact integral of the squared
    piecewise-linear torques. The impulse term of the costs of transport is the work of every
    event that applies the liftoff impulse (:func:`impulse_events`: by the file's contact
    sequence, not by the event's name; a heel-toe walk's impulse acts at ``toe_off``)."""
    model = gait.model
    options = GaitOptions.from_dict(dict(gait.options))
    nq = model.nq
    step, speed = gait.parameters["step_length"], gait.parameters["speed"]
    steps = gait.period_steps  # a stride: two steps, two liftoff impulses, per 2 L
    p = [steps * step, speed, gait.parameters["liftoff_impulse"]]
    total = 0.0
    for ph in gait.phases:
        t_mid = 0.5 * (ph.t[:-1] + ph.t[1:])
        x_mid = phase_states_at(ph, t_mid)
        full = tuple(ph.state_names) == tuple(model.coordinate_names) + tuple(
            f"{n}_rate" for n in model.coordinate_names)
        for k in range(ph.t.size - 1):
            if full:
                qd_mid = x_mid[k, nq:]
            elif ph.name == walking.SINGLE:
                qd_mid = np.asarray(walking.single_support_to_full(model, x_mid[k])[1], float)
            else:
                z, zd = walking.split_state(x_mid[k], len(ph.state_names) // 2)
                qd_mid = np.asarray(double_support_state(model, 0, z, zd, walking.ORIGIN,
                                                         (step, 0.0))[1], float)
            values = [running_cost(model, options, ph.qd[k], list(ph.u[k]), p),
                      running_cost(model, options, qd_mid, list(0.5 * (ph.u[k] + ph.u[k + 1])),
                                   p),
                      running_cost(model, options, ph.qd[k + 1], list(ph.u[k + 1]), p)]
            h = ph.t[k + 1] - ph.t[k]
            total += h / 6.0 * (values[0] + 4.0 * values[1] + values[2])
        total += torque_rate_cost(model, options, ph.t, ph.u)
    impulse = p[2]
    if options.cost == "paper":
        total += steps * impulse * impulse
    else:
        for ev in impulse_events(gait):
            lift = ev.impulses.get(ev.leg)
            if lift is not None:
                phase = next(ph for ph in gait.phases if abs(ph.t[-1] - ev.t) < 1e-12)
                v_after = contact_velocity(model, phase.q[-1], ev.qd_after, ev.leg)
                total += impulse_cost(model, options, lift, v_after, impulse)
        total += parameter_cost(model, options, p)
    return float(total / denominator(model, options, p))


def smoothing_record(gait: Gait) -> dict[str, float] | None:
    """How much of a saved gait's cost of transport is the smoothing of its positive parts
    (``solver.accuracy.smoothing`` of the gait file, docs/costs.md): None for a cost without
    smoothing (the paper's, or ``cost_smoothing`` 0); else

    * ``cost_smoothing``: ``eps`` (W);
    * ``unsmoothed_cost``: ``J0``, the cost of the same motion with ``pos(x) = max(0, x)``
      (:func:`recompute_cost` with ``eps = 0``: the same quadrature), dimensionless;
    * ``share``: ``(J_eps - J0) / J_eps``, ``J_eps`` the smoothed cost by that quadrature.

    ``J0`` is the exact cost of a motion the unsmoothed problem allows, so that problem's
    optimum ``J*`` is at most ``J0``; and at least ``J_eps - n_a eps T / (2 W L)``. Where the
    share is large the smoothing, not the motion, decides the optimum: measured on the costs
    without a resting power, whose speed-free optima slow down as ``eps`` shrinks."""
    options = GaitOptions.from_dict(dict(gait.options))
    if options.cost == "paper" or options.cost_smoothing <= 0.0:
        return None
    smoothed = recompute_cost(gait)
    exact = recompute_cost(dataclasses.replace(
        gait, options={**dict(gait.options), "cost_smoothing": 0.0}))
    return {"cost_smoothing": float(options.cost_smoothing), "unsmoothed_cost": exact,
            "share": (smoothed - exact) / smoothed if smoothed > 0.0 else 0.0}


def impulse_events(gait: Gait) -> list[GaitEvent]:
    """The events of a saved gait that apply the liftoff impulse on their ``leg`` (the NLP's
    Mayer term sums their work, :func:`impulse_cost`): with the file's contact sequence, event
    ``i`` when the sequence's event ``i`` has the same name and ``impulse`` set (the paper's
    walk's ``liftoff``, the heel-toe walk's ``toe_off``); an event the sequence does not
    describe (a file without one, the single-support walk's extra ``liftoff``) by its name,
    ``liftoff``. The rule of the event checks (:mod:`gaitopt.analysis.checks.events`)."""
    specs = (() if gait.contact_sequence is None
             else sequence_from_dict(dict(gait.contact_sequence)).events)
    out: list[GaitEvent] = []
    for i, ev in enumerate(gait.events):
        if i < len(specs) and specs[i].name == ev.name:
            if specs[i].impulse:
                out.append(ev)
        elif ev.name == "liftoff":
            out.append(ev)
    return out
