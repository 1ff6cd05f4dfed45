"""Checking a saved gait independently of the solver.

``verify_gait`` trusts nothing but the file and the model in it. It uses the full-coordinate
dynamics (``gaitopt.dynamics``: the Contact Algorithm with the tips held, the Collision
Algorithm, the liftoff impulse), not the reduced coordinates or the collocation equations the
solver used, and SciPy's adaptive Runge-Kutta integrator (DOP853):

* re-integration from every knot over its interval, and from the start of each phase over the
  whole phase, under the saved controls (piecewise linear, as the transcription), compared with
  the saved knots (the open-loop walk is unstable, so whole-phase drift has a looser limit);
* the heel-strike impact and the liftoff impulse applied to the saved pre-event states,
  compared with the saved post-event velocities and with the next phase's first knot;
* periodicity: the state after liftoff, legs relabelled and shifted back one step, equals the
  first knot; and the controls, if the gait was solved with periodic controls (and the
  paper's control model);
* every constraint on the dense samples: normal contact forces recomputed from the saved
  states and controls, swing clearance, torque bounds, joint limits, tips on the ground;
* the cost recomputed from the saved controls: the exact integral of the squared piecewise-
  linear controls plus the impulse squared, over the step length.

Tolerances (:data:`LIMITS`, all scaled by ``tolerance_scale``): what the transcription imposes
exactly (knots, events, periodicity, cost) is checked to 1e-6; what it cannot impose between
knots is checked against the accuracy of a coarse grid: one interval's re-integration error
0.05 (rad, m, or rad/s / 10), a negative normal force of 1 % of the body weight, 5 mm of
swing-tip penetration, 0.05 rad beyond a joint limit. The paper's 8 + 5 grid reaches these at
high speeds; finer grids pass them with a wide margin (``--tolerance 0.1`` checks them ten
times tighter).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from gaitopt.dynamics.functions import (
    contact_dynamics_function,
    impact_function,
    liftoff_function,
)
from gaitopt.dynamics.kinematics import contact_position
from gaitopt.gait.gait_file import Gait, GaitPhase, leg_swap_permutations
from gaitopt.robot.biped import biped_structure

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Check:
    """One check: its measured ``value`` against ``limit`` (``value <= limit`` passes)."""

    name: str
    value: float
    limit: float
    unit: str = ""
    required: bool = True

    @property
    def passed(self) -> bool:
        """Within the limit; an informational check (``required=False``) always passes."""
        within = bool(np.isfinite(self.value) and self.value <= self.limit)
        return within or not self.required

    @property
    def limit_text(self) -> str:
        text = f"<= {self.limit:.3g} {self.unit}".rstrip()
        return text if self.required else f"({text}, information)"


@dataclass(frozen=True)
class VerifyReport:
    checks: tuple[Check, ...]

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def check(self, name: str) -> Check:
        for c in self.checks:
            if c.name == name:
                return c
        raise KeyError(name)


#: Default limits (scaled by ``tolerance_scale``).
LIMITS = {
    "interval": 5e-2,        # max |state error| after one interval (rad, m; rates / 10)
    "phase": 5e-2,           # position drift over a whole phase (information only)
    "event": 1e-6,           # impact/impulse maps (m/s, rad/s)
    "periodicity": 1e-6,
    "force": 1e-2,           # negative normal force between knots, as a share of body weight
    "clearance": 5e-3,       # m of swing-tip penetration between knots
    "bounds": 1e-6,          # N m or rad beyond a bound at the knots
    "between": 5e-2,         # rad beyond a joint limit between knots
    "tips": 1e-6,            # m off the ground contact point
    "cost": 1e-6,            # relative
}


def _interp_controls(phase: GaitPhase) -> Callable[[float], Array]:
    t, u = phase.t, phase.u

    def at(time: float) -> Array:
        return np.array([np.interp(time, t, u[:, j]) for j in range(u.shape[1])])

    return at


def _integrate(rhs: Callable[[float, Array], Array], t0: float, t1: float, y0: Array) -> Array:
    sol = solve_ivp(rhs, (t0, t1), y0, method="DOP853", rtol=1e-10, atol=1e-10)
    return np.asarray(sol.y[:, -1], dtype=float)


def _state_error(a: Array, b: Array, nq: int) -> float:
    """Max error of positions and of rates / 10 (rates are an order larger)."""
    return float(max(np.max(np.abs(a[:nq] - b[:nq])), np.max(np.abs(a[nq:] - b[nq:])) / 10.0))


def verify_gait(gait: Gait, *, tolerance_scale: float = 1.0) -> VerifyReport:
    """Run every check on ``gait`` (see the module docstring)."""
    model = gait.model
    legs = biped_structure(model).legs
    nq = model.nq
    lim = {k: v * tolerance_scale for k, v in LIMITS.items()}
    checks: list[Check] = []
    step = gait.parameters["step_length"]
    weight = model.total_mass * float(np.hypot(*model.gravity))
    tips_at = {legs[0].contact: np.array([0.0, 0.0]), legs[1].contact: np.array([step, 0.0])}

    interval_err, phase_err, min_force, tip_err = 0.0, 0.0, np.inf, 0.0
    for ph in gait.phases:
        dyn = contact_dynamics_function(model, ph.contacts, inputs="u")
        u_at = _interp_controls(ph)

        def rhs(t: float, y: Array, dyn=dyn, u_at=u_at) -> Array:  # noqa: ANN001
            qdd = np.asarray(dyn(y[:nq], y[nq:], u_at(t))[0], dtype=float).ravel()
            return np.concatenate([y[nq:], qdd])

        y = np.hstack([ph.q, ph.qd])
        for k in range(len(ph.t) - 1):
            end = _integrate(rhs, ph.t[k], ph.t[k + 1], y[k])
            interval_err = max(interval_err, _state_error(end, y[k + 1], nq))
        end = _integrate(rhs, ph.t[0], ph.t[-1], y[0])
        phase_err = max(phase_err, float(np.max(np.abs(end[:nq] - y[-1][:nq]))))
        # Constraints on the dense samples of this phase.
        # Samples belong to the phase they were drawn from: the first phase includes its
        # start, later phases exclude theirs (the sample there has the pre-event velocity).
        t_s = gait.samples.t
        starts_here = ph is gait.phases[0]
        mask = ((t_s >= ph.t[0] - 1e-12) if starts_here else (t_s > ph.t[0] + 1e-12)) & \
            (t_s <= ph.t[-1] + 1e-12)
        qs, qds, us = gait.samples.q[mask], gait.samples.qd[mask], gait.samples.u[mask]
        forces = np.asarray(dyn.map(qs.shape[0])(qs.T, qds.T, us.T)[1], dtype=float)
        min_force = min(min_force, float(np.min(forces[1::2, :])))
        for c in ph.contacts:
            for q in (ph.q[0], ph.q[-1]):
                p = np.asarray(contact_position(model, q, c), dtype=float)
                tip_err = max(tip_err, float(np.max(np.abs(p - tips_at[c]))))
    checks += [
        Check("re-integration per interval", interval_err, lim["interval"], "rad|m"),
        # The open-loop walk is unstable: the local error of the transcription grows over a
        # whole phase, so this drift is reported, not required (the interval check is).
        Check("re-integration per phase (position drift)", phase_err, lim["phase"], "rad|m",
              required=False),
        # Forces hold at the knots and midpoints; between them a coarse grid may dip a little.
        Check("normal contact force on dense samples (negative part)", max(0.0, -min_force),
              lim["force"] * weight, "N"),
        Check("held tips on the ground", tip_err, lim["tips"], "m"),
    ]
    mu = gait.options.get("friction")
    if mu is not None:
        excess = 0.0
        for ph in gait.phases:
            for f in ph.contact_forces.values():
                excess = max(excess, float(np.max(np.abs(f[:, 0]) - mu * f[:, 1])))
        for e in gait.events:
            for c, imp in e.impulses.items():
                if not (e.name == "liftoff" and c == e.leg):
                    excess = max(excess, abs(float(imp[0])) - mu * float(imp[1]))
        checks.append(Check(f"friction cone mu = {mu:g} (excess at knots and events)",
                            max(0.0, excess), lim["event"] * 1e3, "N|N s"))
    checks += _event_checks(gait, lim)
    checks += _sample_checks(gait, lim)
    checks.append(_cost_check(gait, lim))
    return VerifyReport(tuple(checks))


def _event_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    model = gait.model
    legs = biped_structure(model).legs
    events = {e.name: e for e in gait.events}
    strike, lift = events["heel_strike"], events["liftoff"]
    first, last = gait.phases[0], gait.phases[-1]
    q_strike = first.q[-1]
    double = len(gait.phases) > 1
    contacts = (legs[0].contact, legs[1].contact) if double else (legs[1].contact,)
    qd_plus = np.asarray(impact_function(model, contacts)(q_strike, first.qd[-1])[0],
                         dtype=float).ravel()
    event_err = float(np.max(np.abs(qd_plus - strike.qd_after)))
    event_err = max(event_err, float(np.max(np.abs(first.qd[-1] - strike.qd_before))))
    if double:
        event_err = max(event_err, float(np.max(np.abs(gait.phases[1].qd[0] - qd_plus))))
        q_lift = last.q[-1]
        p = gait.parameters["liftoff_impulse"]
        out = liftoff_function(model, legs[0].contact, [legs[1].contact])(q_lift, last.qd[-1], p)
        qd_after = np.asarray(out[0], dtype=float).ravel()
        event_err = max(event_err, float(np.max(np.abs(qd_after - lift.qd_after))))
    else:
        q_lift, qd_after = q_strike, qd_plus
    # Periodicity: relabel legs, shift x back by one step.
    perm_q, perm_u = leg_swap_permutations(model)
    q_next = q_lift[perm_q].copy()
    q_next[0] -= gait.parameters["step_length"]
    qd_next = qd_after[perm_q]
    per = max(float(np.max(np.abs(q_next - first.q[0]))),
              float(np.max(np.abs(qd_next - first.qd[0]))))
    checks = [Check("impact and liftoff maps", event_err, lim["event"], "m/s|rad/s"),
              Check("periodicity of states (legs relabelled)", per, lim["periodicity"])]
    # The "jumps" control model has no control linkages (docs/walking.md, "Control model").
    if (gait.options.get("periodic_controls", True)
            and gait.options.get("control_model", "paper") == "paper"):
        u_next = last.u[-1][perm_u]
        active = np.abs(first.u[0]) > 0  # actuators that act at the start of the step
        both = active & (np.abs(u_next) > 0)
        err = float(np.max(np.abs(u_next[both] - first.u[0][both]), initial=0.0))
        checks.append(Check("periodicity of controls", err, lim["periodicity"] * 1e3, "N m"))
    return checks


def _sample_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    model = gait.model
    s = gait.samples
    u_excess = 0.0
    for j, a in enumerate(model.actuators):
        lo, hi = a.limits
        u_excess = max(u_excess, float(np.max(s.u[:, j] - hi)), float(np.max(lo - s.u[:, j])))
    q_knots = np.vstack([ph.q for ph in gait.phases])
    q_excess, q_between = 0.0, 0.0
    for joint in model.joints:
        i = model.joint_coordinate(joint.name)
        lo, hi = joint.limits
        q_excess = max(q_excess, float(np.max(q_knots[:, i] - hi)),
                       float(np.max(lo - q_knots[:, i])))
        q_between = max(q_between, float(np.max(s.q[:, i] - hi)), float(np.max(lo - s.q[:, i])))
    t1 = gait.parameters["single_support_time"]
    swing = s.points["tip_2"][s.t <= s.t[0] + t1 + 1e-12, 1]
    return [Check("torque bounds (excess)", max(0.0, u_excess), lim["bounds"], "N m"),
            Check("joint limits at knots (excess)", max(0.0, q_excess), lim["bounds"], "rad"),
            # Box bounds hold at the knots; the cubic interpolant may overshoot between them.
            Check("joint limits between knots (excess)", max(0.0, q_between),
                  lim["between"], "rad"),
            Check("swing tip above ground (penetration)", max(0.0, -float(np.min(swing))),
                  lim["clearance"], "m")]


def _cost_check(gait: Gait, lim: dict[str, float]) -> Check:
    total = 0.0
    for ph in gait.phases:
        h = np.diff(ph.t)
        a, b = ph.u[:-1], ph.u[1:]
        total += float(np.sum(h[:, None] * (a * a + a * b + b * b) / 3.0))
    p = gait.parameters["liftoff_impulse"]
    cost = (total + p * p) / gait.parameters["step_length"]
    saved = gait.cost_value
    rel = abs(cost - saved) / max(abs(saved), 1e-12)
    limit = lim["cost"] if gait.options.get("transcription", "hermite-simpson") == \
        "hermite-simpson" else 5e-2
    return Check("cost recomputed from the controls (relative)", rel, limit)
