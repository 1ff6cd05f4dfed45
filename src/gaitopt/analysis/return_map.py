"""The return map of one step, simulated open loop in full coordinates, and its Jacobian.

(One concept, kept whole at about 540 lines: the step's description, its compiled CasADi
functions and the integration across events with the variational equations are one
simulation; the parts are not used apart.)

The Poincare section is the start of single support (just after the liftoff): the stance tip
is at the origin with zero velocity. From a state ``y = [q; qd]`` (2 nq,) on it, one step is

1. **single support** with the stance tip held (:func:`gaitopt.dynamics.contact_dynamics`),
   each phase replaying its torque profile ``u(tau)`` on its own clock ``tau`` (0 at the phase
   start; piecewise linear between knots, the last value held if a perturbed phase runs
   longer), until the guard ``g(q) = y_swing tip = 0`` is crossed moving down with the swing
   tip more than ``arm_distance`` ahead of the origin (where the stance tip stands at the
   step's start; earlier crossings are ignored: the scuffing of a rigid swing leg at
   mid-stance, and the grazing of the ground by optimal gaits whose swing clearance
   constraint is active; a tip still below the ground there must come up first); the
   crossing is found by the integrator's root finder on its dense output
   (state-triggered);
2. the **heel-strike impact** ``qd+ = Delta(q, qd-)`` (:func:`gaitopt.dynamics.impact`) with the
   contacts held in double support (or the striking tip alone when the gait has none);
3. **double support** for a fixed duration (time-triggered);
4. the **liftoff impulse** of the gait's magnitude (:func:`gaitopt.dynamics.liftoff_impulse`);
5. the **leg swap** (the linear map ``S`` of :func:`gaitopt.robot.symmetry.swap_matrices`)
   and the shift of the base position by the new stance tip's position, so that it is at
   the origin: ``q+ = S q - E c(S q)``, ``qd+ = S qd`` (``E`` puts the 2-vector on ``x, y``).

That is the paper's walk; in general (:class:`StepSpec`) the phases run in order, those
that end when a point strikes the ground are state-triggered (each with its own guard: the
height of the point that strikes, :attr:`PhaseProfile.guard`) and the others last their
durations, and after each phase its :class:`StepEvent` jumps (impacts, liftoffs) are
applied in order, then the swap. A run is stance (time-triggered), the toe-off (a liftoff
without impulse, no contact held after it), flight (no contact held) until the swing tip
strikes (the guard), the touchdown impact, the swap. A walk with feet (heel-toe) has two
guards: the heel strike, and the toe of the same foot landing at the end of the heel
rocker (foot flat); its section is the start of foot flat, with the stance heel pinned at
the origin and the stance toe held on the ground (:attr:`StepSpec.section_holds`).

Optional joint-space PD tracking adds ``u = kp B^T (q_ref(tau) - q) + kd B^T (qd_ref(tau) -
qd)`` to the replayed torques (``B`` the actuation matrix of the phase, so a joint actuator
tracks its joint angle and an ankle its link's absolute angle); the torques are not bounded.

The Jacobian of the map (the monodromy, ``(2 nq, 2 nq)``) is computed from variational
equations ``Phi' = A(tau) Phi`` (``A = d f / d y`` by CasADi) integrated with the state, the
Jacobians of the jump maps, and at the guard the matrix ``DDelta (I - f- Dg / (Dg f-))``: the
classical saltation matrix ``Xi = DDelta + (f+ - DDelta f-) Dg / (Dg f-)`` minus ``f+ Dg /
(Dg f-)``, because the next phase runs on its own clock from the event (a step that strikes
``dt`` early starts double support ``dt`` early, so its state at a fixed clock time carries no
``f+ dt`` term). :func:`saltation_matrix` gives the classical ``Xi``.

Nothing here depends on the legs of a particular model: only contacts, the two-contact leg
swap and the actuators.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import casadi as ca
import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from gaitopt.analysis.numeric import evaluate, numeric_function
from gaitopt.codegen import CompileError, compile_functions
from gaitopt.dynamics.actuation import actuation_rows
from gaitopt.dynamics.functions import (
    contact_dynamics_function,
    impact_function,
    liftoff_function,
)
from gaitopt.dynamics.kinematics import contact_position, contact_velocity
from gaitopt.dynamics.tree import holds
from gaitopt.ocp.hermite_simpson import HermiteSimpson
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import swap_matrices

Array = NDArray[np.float64]


class StepSimulationError(ValueError):
    """The simulated step did not reach its events (e.g. the swing tip never strikes)."""


@dataclass(frozen=True, eq=False)
class PhaseProfile:
    """One phase replayed on its own clock (``tau = 0`` at the phase start).

    ``contacts`` held (hold specs, as :func:`gaitopt.dynamics.tree.holds` reads them);
    ``duration`` (s), or None when the phase ends at a guard: the point ``guard`` (default:
    the step's swing tip) reaching the ground moving down; knot times
    ``t`` (K,) on the phase clock; torques ``u`` (K, nu) N m; for PD tracking the reference
    ``q``, ``qd``, ``qdd`` (K, nq) at the knots (``q_ref`` is the cubic Hermite interpolant of
    ``q`` and ``qd``, ``qd_ref`` that of ``qd`` and ``qdd``; last values held past the end).
    """

    contacts: tuple[str, ...]
    duration: float | None
    t: Array
    u: Array
    q: Array | None = None
    qd: Array | None = None
    qdd: Array | None = None
    nominal_duration: float = 0.0
    guard: str | None = None

    def inputs(self, tau: float) -> tuple[Array, Array | None, Array | None]:
        """``(u, q_ref, qd_ref)`` at ``tau`` (the references None without PD knots)."""
        t = self.t
        k = min(max(int(np.searchsorted(t, tau, side="right")) - 1, 0), t.size - 2)
        h = t[k + 1] - t[k]
        s = min(max((tau - t[k]) / h, 0.0), 1.0)
        u = (1.0 - s) * self.u[k] + s * self.u[k + 1]
        if self.q is None or self.qd is None or self.qdd is None:
            return u, None, None
        if tau >= t[-1]:
            return u, self.q[-1], self.qd[-1]
        hermite = HermiteSimpson()  # the transcription's interpolant of q and of qd
        q = hermite.state_at(s, self.q[k], self.q[k + 1], self.qd[k], self.qd[k + 1], h)
        qd = hermite.state_at(s, self.qd[k], self.qd[k + 1], self.qdd[k], self.qdd[k + 1], h)
        return u, q, qd


@dataclass(frozen=True)
class StepEvent:
    """A jump between phases: ``kind`` "strike" (an inelastic impact after which the
    ``contacts`` are at rest: the striking ``contact`` and those held next) or "liftoff" (the
    ``contact`` leaves with an impulse of ``magnitude`` N s along the leg while the
    ``contacts`` stay held)."""

    kind: str
    contact: str
    contacts: tuple[str, ...]
    magnitude: float = 0.0


@dataclass(frozen=True, eq=False)
class StepSpec:
    """Everything the return map needs: the model, the stance and swing contacts, the phases
    in order (at least one ends at a guard: ``duration`` None; the others last their
    ``duration``), the events after each phase (``events[i]``, applied in order), the
    distance (m) a guard's point must be ahead of the origin (the stance tip at the start of
    the step) before its guard is armed, optional PD gains ``(kp, kd)`` (N m/rad,
    N m s/rad), the integrator tolerances, and the holds that define the Poincare section
    (``section_holds``: the points held at rest at the step's start, as hold specs; default
    the stance tip pinned)."""

    model: RobotModel
    stance: str
    swing: str
    phases: tuple[PhaseProfile, ...]
    events: tuple[tuple[StepEvent, ...], ...]
    arm_distance: float = 0.0
    pd: tuple[float, float] | None = None
    rtol: float = 1e-11
    atol: float = 1e-11
    section_holds: tuple[str, ...] = ()
    _functions: dict[str, ca.Function] = field(default_factory=dict, repr=False)

    @cached_property
    def nq(self) -> int:
        return self.model.nq

    @cached_property
    def guard_phases(self) -> tuple[int, ...]:
        """Indices of the phases that end at a guard (state-triggered), in order."""
        guards = tuple(i for i, ph in enumerate(self.phases) if ph.duration is None)
        if not guards or len(self.events) != len(self.phases):
            raise StepSimulationError("a step needs at least one guard-terminated phase and a "
                                      "list of events after each phase")
        return guards

    @cached_property
    def guard_phase(self) -> int:
        """Index of the first phase that ends at a guard (the heel strike of a walk)."""
        return self.guard_phases[0]

    @cached_property
    def holds(self) -> tuple[str, ...]:
        """The section's holds (:attr:`section_holds`, or the stance tip pinned)."""
        return self.section_holds or (self.stance,)

    def guard_point(self, phase: int) -> str:
        """The point whose touchdown ends phase ``phase`` (the swing tip by default)."""
        return self.phases[phase].guard or self.swing

    def function(self, key: str, build: Callable[[], ca.Function]) -> ca.Function:
        if key not in self._functions:
            self._functions[key] = build()
        return self._functions[key]


@dataclass(frozen=True, eq=False)
class StepResult:
    """One simulated step: ``y_next`` (2 nq,) on the section; the guard crossing (phase-clock
    time ``strike_time``, pre-impact state ``y_strike``); the state after the heel strike's
    events and after the last phase's events; the step time; with ``variational=True`` the
    monodromy ``(2 nq, 2 nq)`` and its factors: ``phi_i`` (phase i's flow), ``jump_i`` (the
    events after it, with the guard factor ``I - f- Dg / (Dg f-)`` for the guard phase) and
    ``jump_swap``."""

    y_next: Array
    strike_time: float
    y_strike: Array
    y_impact: Array
    y_liftoff: Array
    step_time: float
    monodromy: Array | None = None
    factors: dict[str, Array] = field(default_factory=dict)


# -- CasADi functions ---------------------------------------------------------------------------

def _compiled(spec: StepSpec, function: ca.Function) -> ca.Function:
    """``function`` compiled to C (cached on disk by its source; see :mod:`gaitopt.codegen`),
    or as it is if no C compiler works (slower, same results)."""
    name = f"gaitopt_stability_{spec.model.content_hash()}_{function.name()}"
    try:
        return compile_functions([function], re.sub(r"\W", "_", name))[function.name()]
    except CompileError:
        return function


def _rhs(spec: StepSpec, contacts: tuple[str, ...], jacobian: bool = True) -> ca.Function:
    """``rhs(y, u_ff, q_ref, qd_ref, gains) -> ydot (2nq)`` and, with ``jacobian``, also
    ``A = d ydot / d y (2nq, 2nq)``; compiled. ``gains`` (2,) = ``(kp, kd)`` is an input (one
    compiled function serves every pair of gains, as a search over gains needs); it is
    ignored without PD (``spec.pd`` None)."""
    model, nq = spec.model, spec.nq
    tag = "_".join([*contacts, "open" if spec.pd is None else "pd", "A" if jacobian else "f"])

    def build() -> ca.Function:
        y, uff = ca.SX.sym("y", 2 * nq), ca.SX.sym("u", model.nu)
        q_ref, qd_ref = ca.SX.sym("q_ref", nq), ca.SX.sym("qd_ref", nq)
        gains = ca.SX.sym("gains", 2)
        q, qd = y[:nq], y[nq:]
        u = uff
        if spec.pd is not None and model.nu:
            kp, kd = gains[0], gains[1]
            bt = ca.DM(np.array(actuation_rows(model, contacts), dtype=float).T)
            u = uff + kp * ca.mtimes(bt, q_ref - q) + kd * ca.mtimes(bt, qd_ref - qd)
        qdd = contact_dynamics_function(model, contacts, inputs="u")(q, qd, u)[0]
        ydot = ca.vertcat(qd, qdd)
        outputs = [ydot, ca.jacobian(ydot, y)] if jacobian else [ydot]
        name = re.sub(r"_+", "_", re.sub(r"\W", "_", f"rhs_{tag}"))
        return _compiled(spec, ca.Function(name, [y, uff, q_ref, qd_ref, gains], outputs))

    return spec.function("rhs:" + tag, build)


def _gains(spec: StepSpec) -> Array:
    """The PD gains ``(kp, kd)`` (2,) as the compiled right-hand side takes them (0 without
    PD)."""
    return np.zeros(2) if spec.pd is None else np.array(spec.pd, dtype=float)


def _tip(spec: StepSpec, contact: str) -> ca.Function:
    """``tip(y) -> (position (2), velocity (2), d[position; velocity] / dy (4, 2nq))``."""
    model, nq = spec.model, spec.nq

    def build() -> ca.Function:
        y = ca.SX.sym("y", 2 * nq)
        p = contact_position(model, y[:nq], contact)
        v = contact_velocity(model, y[:nq], y[nq:], contact)
        pv = ca.vertcat(p, v)
        return _compiled(spec, ca.Function(f"tip_{contact}", [y], [p, v, ca.jacobian(pv, y)]))

    return spec.function("tip:" + contact, build)


def _event_jump(spec: StepSpec, event: StepEvent) -> ca.Function:
    """``jump(y-) -> (y+, d y+ / d y-)`` of an impact or a liftoff impulse."""
    nq = spec.nq

    def build() -> ca.Function:
        y = ca.SX.sym("y", 2 * nq)
        if event.kind == "strike":
            qd_plus = impact_function(spec.model, event.contacts)(y[:nq], y[nq:])[0]
        else:
            f = liftoff_function(spec.model, event.contact, event.contacts)
            qd_plus = f(y[:nq], y[nq:], event.magnitude)[0]
        out = ca.vertcat(y[:nq], qd_plus)
        return ca.Function("jump", [y], [out, ca.jacobian(out, y)])

    return spec.function(f"jump:{event!r}", build)


def _swap_jump(spec: StepSpec) -> ca.Function:
    """``swap(y) -> (y+, d y+ / d y)``: legs exchanged, base shifted so that the new stance
    tip (the stance contact after relabelling) is at the origin."""
    nq = spec.nq
    s_q = ca.DM(swap_matrices(spec.model)[0])

    def build() -> ca.Function:
        y = ca.SX.sym("y", 2 * nq)
        q = ca.mtimes(s_q, y[:nq])
        tip = contact_position(spec.model, q, spec.stance)
        shift = ca.vertcat(tip, ca.SX.zeros(nq - 2))
        out = ca.vertcat(q - shift, ca.mtimes(s_q, y[nq:]))
        return ca.Function("swap", [y], [out, ca.jacobian(out, y)])

    return spec.function("swap", build)


# -- integration --------------------------------------------------------------------------------

def _phase_function(spec: StepSpec, phase: PhaseProfile, jacobian: bool
                    ) -> Callable[[float, Array], list[Array]]:
    """``(tau, y) -> [f (2 nq, 1)]``, with ``jacobian`` ``[f, A (2 nq, 2 nq)]``: the phase's
    vector field at ``tau``, its compiled function and gains looked up once (an integrator
    calls it tens of thousands of times)."""
    fn = numeric_function(_rhs(spec, phase.contacts, jacobian=jacobian))
    gains = _gains(spec)
    zero = np.zeros(spec.nq)

    def at(tau: float, y: Array) -> list[Array]:
        u, q_ref, qd_ref = phase.inputs(tau)
        return fn(y, u, zero if q_ref is None else q_ref, zero if qd_ref is None else qd_ref,
                  gains)

    return at


def phase_rhs(spec: StepSpec, phase: PhaseProfile, tau: float, y: Array) -> tuple[Array, Array]:
    """The vector field ``f(tau, y)`` (2 nq,) of a phase and its Jacobian ``A`` (2 nq, 2 nq)."""
    ydot, a = _phase_function(spec, phase, jacobian=True)(tau, y)
    return ydot.ravel(), a


def phase_field(spec: StepSpec, phase: PhaseProfile, tau: float, y: Array) -> Array:
    """The vector field ``f(tau, y)`` (2 nq,) of a phase."""
    return _phase_function(spec, phase, jacobian=False)(tau, y)[0].ravel()


def _integrate_phase(spec: StepSpec, phase: PhaseProfile, y0: Array, variational: bool,
                     until: float | None = None, tau0: float = 0.0,
                     guard: bool | None = None) -> tuple[float, Array, Array | None]:
    """Integrate a phase from ``tau0`` (0: the phase start); stop at ``until`` (if given and
    ``guard`` is not True), at ``phase.duration`` (time-triggered), or at the guard
    (``duration`` None, or ``guard=True``). Returns ``(tau_end, y, Phi)``."""
    n = 2 * spec.nq
    point = phase.guard or spec.swing
    tip = numeric_function(_tip(spec, point))
    field = _phase_function(spec, phase, jacobian=variational)

    def rhs(tau: float, z: Array) -> Array:
        if not variational:
            return field(tau, z)[0].ravel()
        ydot, a = field(tau, z[:n])
        return np.concatenate([ydot.ravel(), (a @ z[n:].reshape(n, n)).ravel()])

    def ahead(tau: float, z: Array) -> float:
        # From the origin, where the stance tip stands at the start of the step (and, held,
        # all through a walk's single support; a run's flight holds no tip).
        return float(tip(z[:n])[0][0, 0] - spec.arm_distance)

    def height(tau: float, z: Array) -> float:
        return float(tip(z[:n])[0][1, 0])

    ahead.terminal, ahead.direction = True, 1.0  # type: ignore[attr-defined]
    height.terminal, height.direction = True, -1.0  # type: ignore[attr-defined]
    if guard is None:
        guard = phase.duration is None and until is None
    end = until if until is not None and not guard else phase.duration
    if end is None:  # state-triggered: search up to three nominal durations
        end = 3.0 * max(phase.nominal_duration, float(phase.t[-1]))
    breaks = [b for b in phase.t if tau0 < b < end] + [end]
    z = np.concatenate([y0, np.eye(n).ravel()]) if variational else np.asarray(y0, float)
    tau, armed = tau0, ahead(tau0, z) > 0.0
    for stop in breaks:
        while tau < stop:
            events = ([height] if armed else [ahead]) if guard else None
            sol = solve_ivp(rhs, (tau, stop), z, method="DOP853", rtol=spec.rtol,
                            atol=spec.atol, events=events)
            if not sol.success:
                raise StepSimulationError(f"the integrator failed in a phase holding "
                                          f"{', '.join(phase.contacts)}: {sol.message}")
            if sol.status == 1:
                tau, z = float(sol.t_events[0][0]), np.asarray(sol.y_events[0][0], float)
                if armed:
                    return tau, z[:n], (z[n:].reshape(n, n) if variational else None)
                armed = True
                continue
            tau, z = stop, np.asarray(sol.y[:, -1], float)
    if guard:
        raise StepSimulationError(f"the point {point} did not strike the ground ahead "
                                  f"of the stance tip within {end:.3g} s of single support")
    return tau, z[:n], (z[n:].reshape(n, n) if variational else None)


def guard_row(spec: StepSpec, y: Array, point: str | None = None) -> Array:
    """``Dg`` (2 nq,): the gradient of a guard (the height of ``point``, by default the swing
    tip) with respect to ``y``."""
    return evaluate(_tip(spec, point or spec.swing), y)[2][1]


def guard_factor(spec: StepSpec, phase: int, tau: float, y_minus: Array) -> Array:
    """``I - f- Dg / (Dg f-)`` (2 nq, 2 nq) at the guard ending phase ``phase`` (module
    docstring), ``f-`` the phase's field at the crossing (clock ``tau``, state ``y_minus``)."""
    f_minus = phase_field(spec, spec.phases[phase], tau, y_minus)
    dg = guard_row(spec, y_minus, spec.guard_point(phase))
    rate = float(dg @ f_minus)
    if abs(rate) < 1e-12:
        raise StepSimulationError(f"the point {spec.guard_point(phase)} grazes the ground at "
                                  "its touchdown (zero vertical velocity): the saltation "
                                  "matrix is undefined")
    return np.eye(2 * spec.nq) - np.outer(f_minus, dg) / rate


def saltation_matrix(spec: StepSpec, y_minus: Array, f_minus: Array, f_plus: Array) -> Array:
    """The classical saltation matrix ``Xi = DDelta + (f+ - DDelta f-) Dg / (Dg f-)``
    (2 nq, 2 nq) of the heel strike at the pre-impact state ``y_minus``: it maps a
    perturbation just before the crossing time to the perturbation just after it, both at the
    same time. ``f_minus``/``f_plus`` are the vector fields before and after the event."""
    _, d_delta = impact_jump(spec, y_minus)
    dg = guard_row(spec, y_minus)
    rate = float(dg @ f_minus)
    if abs(rate) < 1e-12:
        raise StepSimulationError("the swing tip grazes the ground at the heel strike "
                                  "(zero vertical velocity): the saltation matrix is undefined")
    return d_delta + np.outer(f_plus - d_delta @ f_minus, dg) / rate


def event_jump(spec: StepSpec, event: StepEvent, y_minus: Array) -> tuple[Array, Array]:
    """An event's jump ``y+ = (q, qd+(q, qd-))`` (2 nq,) and its Jacobian (2 nq, 2 nq)."""
    y_plus, jac = evaluate(_event_jump(spec, event), np.asarray(y_minus, float))
    return y_plus.ravel(), jac


def events_jump(spec: StepSpec, events: tuple[StepEvent, ...],
                y_minus: Array) -> tuple[Array, Array]:
    """The events after a phase applied in order: ``(y+, d y+ / d y-)``."""
    y, jac = np.asarray(y_minus, float), np.eye(2 * spec.nq)
    for event in events:
        y, d = event_jump(spec, event, y)
        jac = d @ jac
    return y, jac


def impact_jump(spec: StepSpec, y_minus: Array) -> tuple[Array, Array]:
    """The heel-strike jump (the events after the guard phase), ``(y+, Jacobian)``."""
    return events_jump(spec, spec.events[spec.guard_phase], y_minus)


def simulate_step(spec: StepSpec, y0: Array, *, variational: bool = False) -> StepResult:
    """One step of the return map from ``y0`` (2 nq,) (see the module docstring)."""
    y = np.asarray(y0, dtype=float)
    n = 2 * spec.nq
    guard, guards = spec.guard_phase, spec.guard_phases
    monodromy = np.eye(n)
    factors: dict[str, Array] = {}
    t_total, t_strike, y_strike, y_imp = 0.0, 0.0, y, y
    for i, (phase, events) in enumerate(zip(spec.phases, spec.events, strict=True)):
        tau, y_end, phi = _integrate_phase(spec, phase, y, variational)
        t_total += tau
        y, jump = events_jump(spec, events, y_end)
        if i == guard:
            t_strike, y_strike, y_imp = tau, y_end, y
        if variational:
            assert phi is not None
            if i in guards:
                jump = jump @ guard_factor(spec, i, tau, y_end)
            factors[f"phi_{i}"], factors[f"jump_{i}"] = phi, jump
            monodromy = jump @ phi @ monodromy
    y_next, d_swap = evaluate(_swap_jump(spec), y)
    factors["jump_swap"] = d_swap
    return StepResult(y_next=y_next.ravel(), strike_time=t_strike, y_strike=y_strike,
                      y_impact=y_imp, y_liftoff=y, step_time=t_total,
                      monodromy=d_swap @ monodromy if variational else None,
                      factors=factors if variational else {})


def integrate_phase(spec: StepSpec, phase: PhaseProfile, y0: Array, until: float | None = None,
                    *, tau0: float = 0.0, guard: bool | None = None,
                    variational: bool = False) -> tuple[float, Array, Array | None]:
    """Integrate ``phase`` from ``y0`` at clock time ``tau0`` to ``until``, to its duration,
    or (``guard=True``, or a state-triggered phase without ``until``) to the heel-strike
    guard: ``(tau_end, y_end (2 nq,), Phi (2 nq, 2 nq) or None)``."""
    return _integrate_phase(spec, phase, np.asarray(y0, float), variational, until, tau0, guard)


def step_map(spec: StepSpec, y0: Array) -> Array:
    """``P(y0)``: the state (2 nq,) at the start of the next step (no Jacobian)."""
    return simulate_step(spec, y0).y_next


def section_constraints(spec: StepSpec, y: Array) -> tuple[Array, Array]:
    """The held coordinates of the section's points (:attr:`StepSpec.holds`): positions then
    velocities, ``(2 m,)`` for ``m`` held axes (4 for the stance tip pinned: x, y, vx, vy),
    and their Jacobian ``C`` (2 m, 2 nq): ``C = [[J, 0], [d(J qd)/dq, J]]``, rows of the held
    axes. The section is ``{position = position at the start, velocity = 0}`` (the stance tip
    at the origin; a point held along the normal only at height 0)."""
    rows_p, rows_v, jac_p, jac_v = [], [], [], []
    for hold in holds(spec.model, spec.holds, "section_holds"):
        p, v, c = evaluate(_tip(spec, hold.name), np.asarray(y, float))
        axes = list(hold.axes)
        rows_p.append(p.ravel()[axes])
        rows_v.append(v.ravel()[axes])
        jac_p.append(c[axes])
        jac_v.append(c[[2 + a for a in axes]])
    return (np.concatenate(rows_p + rows_v), np.vstack(jac_p + jac_v))


def reference_step(spec: StepSpec) -> StepResult:
    """The monodromy linearized about the phases' own reference trajectories (the gait's knots
    interpolated: ``q`` cubic Hermite with ``qd``, ``qd`` with ``qdd``) instead of a simulated
    step: ``Phi' = A(tau, y_ref(tau)) Phi`` over each phase's knots, the jump Jacobians at the
    saved pre-event states, and the guard factor with ``f-`` the model's vector field at the
    saved pre-impact state. ``y_next`` is the gait's own next start (its periodicity residual
    is the transcription's)."""
    n = 2 * spec.nq
    for ph in spec.phases:
        if ph.q is None or ph.qd is None:
            raise StepSimulationError("linearizing about the gait needs its knots")

    def reference(ph: PhaseProfile, tau: float) -> Array:
        _, q, qd = ph.inputs(tau)
        assert q is not None and qd is not None
        return np.concatenate([q, qd])

    def along(ph: PhaseProfile) -> Array:
        def rhs(tau: float, z: Array) -> Array:
            _, a = phase_rhs(spec, ph, tau, reference(ph, tau))
            return (a @ z.reshape(n, n)).ravel()

        z, tau = np.eye(n).ravel(), 0.0
        for stop in [b for b in ph.t if b > 0.0]:
            sol = solve_ivp(rhs, (tau, float(stop)), z, method="DOP853", rtol=spec.rtol,
                            atol=spec.atol)
            z, tau = np.asarray(sol.y[:, -1], float), float(stop)
        return z.reshape(n, n)

    guard, guards = spec.guard_phase, spec.guard_phases
    monodromy = np.eye(n)
    factors: dict[str, Array] = {}
    t_total, t_strike = 0.0, 0.0
    y_strike = y_imp = y = reference(spec.phases[0], 0.0)
    for i, (phase, events) in enumerate(zip(spec.phases, spec.events, strict=True)):
        tau = float(phase.t[-1])
        y_end = reference(phase, tau)
        t_total += tau
        y, jump = events_jump(spec, events, y_end)
        if i in guards:
            jump = jump @ guard_factor(spec, i, tau, y_end)
        if i == guard:
            t_strike, y_strike, y_imp = tau, y_end, y
        factors[f"phi_{i}"], factors[f"jump_{i}"] = along(phase), jump
        monodromy = jump @ factors[f"phi_{i}"] @ monodromy
    y_next, d_swap = evaluate(_swap_jump(spec), y)
    factors["jump_swap"] = d_swap
    return StepResult(y_next=y_next.ravel(), strike_time=t_strike, y_strike=y_strike,
                      y_impact=y_imp, y_liftoff=y, step_time=t_total,
                      monodromy=d_swap @ monodromy, factors=factors)
