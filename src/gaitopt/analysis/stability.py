"""Orbital stability of a gait: the Floquet multipliers of its step-to-step return map.

(One concept, kept whole at about 490 lines: from a gait (or its contact sequence) to its
step, the section, the multipliers and the report are one analysis; the simulation itself is
in :mod:`.return_map`.)

``gait_stability(gait)`` builds the return map of one step (:mod:`.return_map`: the gait's
own torques replayed open loop, optionally with joint-space PD tracking), takes its Jacobian
(the monodromy, ``(2 nq, 2 nq)`` in full coordinates ``y = [q; qd]``) at the gait's start state
(or at the nearby fixed point found by Newton's method), and restricts it to the Poincare
section: the start of single support, where the stance tip is at the origin with zero
velocity. The section's tangent space at ``y*`` is ``{C dy = 0}`` with
``C = [[J, 0], [d(J qd)/dq, J]]`` (4, 2 nq), ``J`` the stance tip's Jacobian; with ``V`` an
orthonormal basis of it (2 nq - 4 columns), the multipliers are the eigenvalues of
``V^T Phi V``. The four removed directions are the stance tip's position and velocity, which
the map holds at zero (the contact constraints).

Further directions are removed only when a link rotates freely (a body whose absolute angle
has no coupling in the mass matrix, no gravity moment, no contact point and no actuator at the
states of the step, and that the leg swap maps to itself, such as a point-mass hip modelled as
a base link of tiny inertia): its angle and rate span an invariant subspace on which the map
is ``[[1, T], [0, 1]]`` (two multipliers at 1 with a Jordan block), and the multipliers are
those of the map on the quotient. Every multiplier within ``1e-3`` of 1 left afterwards, and
the image of the flow direction (the map of an autonomous system sends it to 0), are reported
in ``notes``.

The monodromy is computed two independent ways: variational equations with saltation
matrices (:func:`.return_map.simulate_step`) and central finite differences of the simulated
map along ``V`` (``check=True``); ``fd_agreement`` is their largest difference relative to
the largest entry.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.return_map import (
    PhaseProfile,
    StepEvent,
    StepSimulationError,
    StepSpec,
    phase_field,
    reference_step,
    section_constraints,
    simulate_step,
    step_map,
)
from gaitopt.dynamics.actuation import actuation_rows
from gaitopt.dynamics.crba import crba
from gaitopt.dynamics.kinematics import contact_jacobian, contact_position
from gaitopt.dynamics.rnea import gravity_forces
from gaitopt.dynamics.tree import holds
from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.contact_sequence import ContactSequenceError, sequence_from_dict
from gaitopt.robot.model import BASE_POSITION
from gaitopt.robot.symmetry import leg_swap, swap_matrices

Array = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

About = Literal["simulation", "gait"]

#: The heel-strike guard of a gait is armed once the swing tip is this fraction of the step
#: length ahead of the stance tip (optimal gaits graze the ground earlier: their clearance
#: constraint is active in mid-swing).
ARM_FRACTION = 0.5

#: Gait-file events that land a contact (an inelastic impact: the walk's heel strike, the
#: run's touchdown after the flight) and that release one (with or without an impulse).
STRIKE_EVENTS: tuple[str, ...] = ("heel_strike", "touchdown")
RELEASE_EVENTS: tuple[str, ...] = ("liftoff", "toe_off")

#: Step of the central differences along the section's tangent basis (rad, m, rad/s, m/s).
#: The five-link gaits' maps are strongly nonlinear (their swing tip lands almost tangentially,
#: so the heel-strike time is very sensitive): 1.3e-6 relative agreement at 1e-6, 1.3e-4 at
#: 1e-5 (PD 300, 30); the smoother compass map prefers 1e-5 (5e-6; 7e-5 at 1e-6).
FD_STEP = 1e-6

#: Multipliers this close to 1 are reported as "at 1".
UNIT_TOLERANCE = 1e-3


class StabilityError(ValueError):
    """The gait cannot be analysed (failed solve, unsupported phase structure, bad gains)."""


@dataclass(frozen=True)
class RemovedDirections:
    """Directions of the full state space left out of the multipliers, and why."""

    name: str
    reason: str
    count: int
    multipliers: tuple[complex, ...] = ()


@dataclass(frozen=True, eq=False)
class StabilityReport:
    """Floquet multipliers of a gait's return map (see the module docstring).

    ``multipliers`` (complex, sorted by modulus, largest first); ``verdict`` "stable" if the
    spectral radius is < 1 - ``margin``, "unstable" if > 1 + ``margin``, else "marginal";
    ``fixed_point``: "gait start" or "Newton fixed point"; ``residual``: ``max |P(y) - y|`` at the
    analysed state (rad, m, rad/s, m/s) and ``start_residual`` at the gait's own start state;
    ``monodromy`` (2 nq, 2 nq) from the variational equations, ``section_monodromy`` on the
    tangent basis ``basis`` (2 nq, m); ``fd_agreement``: the finite-difference check (None if
    not run)."""

    multipliers: ComplexArray
    spectral_radius: float
    verdict: str
    margin: float
    removed: tuple[RemovedDirections, ...]
    notes: tuple[str, ...]
    fixed_point: str
    residual: float
    start_residual: float
    state: Array
    step_time: float
    monodromy: Array
    section_monodromy: Array
    basis: Array
    fd_agreement: float | None
    settings: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data (multipliers as ``[re, im]``, modulus and angle in degrees)."""
        return {
            "multipliers": [{"re": float(m.real), "im": float(m.imag), "modulus": float(abs(m)),
                             "angle_deg": float(np.degrees(np.angle(m)))}
                            for m in self.multipliers],
            "spectral_radius": self.spectral_radius, "verdict": self.verdict,
            "margin": self.margin,
            "removed": [{"name": r.name, "reason": r.reason, "count": r.count,
                         "multipliers": [[float(m.real), float(m.imag)] for m in r.multipliers]}
                        for r in self.removed],
            "notes": list(self.notes), "fixed_point": self.fixed_point,
            "residual": self.residual, "start_residual": self.start_residual,
            "state": self.state.tolist(), "step_time": self.step_time,
            "fd_agreement": self.fd_agreement, "settings": dict(self.settings),
        }


# -- from a gait file to a step ----------------------------------------------------------------

def step_from_gait(gait: Gait, *, pd: tuple[float, float] | None = None,
                   rtol: float = 1e-10) -> StepSpec:
    """The return map of ``gait``'s step: its phases, contacts, events and liftoff impulse."""
    if not gait.success:
        raise StabilityError(f"the gait's solve did not converge (status {gait.status!r}): "
                             "its trajectories are not a gait; solve it again")
    if pd is not None and (len(pd) != 2 or not all(np.isfinite(pd)) or min(pd) < 0):
        raise StabilityError(f"pd: got {pd!r}; allowed: two finite gains kp, kd >= 0")
    if gait.period_steps != 1:
        raise StabilityError(f"contact_sequence.steps = {gait.period_steps}: the return map of "
                             "a stride (two steps, no leg swap) is not implemented; only of "
                             "one step periodic through the leg swap")
    if gait.contact_sequence is not None:
        return _step_from_sequence(gait, pd, rtol)
    phases = gait.phases
    if len(phases[0].contacts) != 1:
        raise StabilityError(f"phases[0].contacts: the step must start in single support on "
                             f"one contact, got {list(phases[0].contacts)}")
    stance = phases[0].contacts[0]
    strikes = [e for e in gait.events if e.name in STRIKE_EVENTS]
    if len(strikes) != 1:
        raise StabilityError(f"events: expected one touchdown event ({' or '.join(STRIKE_EVENTS)}"
                             f") per step, got {len(strikes)}")
    swing = strikes[0].leg
    unknown = [e.name for e in gait.events if e.name not in STRIKE_EVENTS + RELEASE_EVENTS]
    if unknown:
        raise StabilityError(f"events: {unknown[0]!r} is neither a touchdown "
                             f"({', '.join(STRIKE_EVENTS)}) nor a release "
                             f"({', '.join(RELEASE_EVENTS)})")
    ends = [float(ph.t[-1]) for ph in phases]
    events: list[list[StepEvent]] = [[] for _ in phases]
    guard = -1
    # At one instant the strike comes first (the single-support walk: strike, then release).
    for e in sorted(gait.events, key=lambda e: e.name not in STRIKE_EVENTS):
        i = int(np.argmin([abs(e.t - t) for t in ends]))
        if abs(e.t - ends[i]) > 1e-9:
            raise StabilityError(f"events: {e.name} at {e.t:g} s is not at the end of a phase")
        after = phases[i + 1].contacts if i + 1 < len(phases) else (swing,)
        if e.name in STRIKE_EVENTS:
            guard = i
            events[i].append(StepEvent("strike", e.leg, tuple(dict.fromkeys((*after, e.leg)))))
        else:
            impulse = e.impulses.get(e.leg)
            magnitude = 0.0 if impulse is None else float(np.hypot(*impulse))
            events[i].append(StepEvent("liftoff", e.leg, tuple(c for c in after if c != e.leg),
                                       magnitude))

    def profile(i: int) -> PhaseProfile:
        ph = phases[i]
        return PhaseProfile(contacts=ph.contacts, duration=None if i == guard else ph.duration,
                            t=ph.t - ph.t[0], u=np.array(ph.u), q=np.array(ph.q),
                            qd=np.array(ph.qd), qdd=np.array(ph.qdd),
                            nominal_duration=ph.duration)

    return StepSpec(model=gait.model, stance=stance, swing=swing,
                    phases=tuple(profile(i) for i in range(len(phases))),
                    events=tuple(tuple(ev) for ev in events),
                    arm_distance=ARM_FRACTION * gait.step_length, pd=pd, rtol=rtol, atol=rtol)


def _step_from_sequence(gait: Gait, pd: tuple[float, float] | None, rtol: float) -> StepSpec:
    """The return map of a gait that carries its contact sequence (any sequence of the
    transcription, e.g. heel-toe): each phase holds the sequence's hold specs; a phase
    followed by a touchdown is state-triggered, its guard the height of the point that
    touches down (the first, if several); after it the impact of the points held next
    (as the transcription's event map does); a release is a liftoff with the gait's
    impulse (0 without one, or after a touchdown at the same instant: then it only projects
    the velocity onto the held points' constraints, which the state already meets); the
    section holds the first phase's points at rest, the stance point the first of them held
    on both axes, the swing point the first that touches down.
    """
    try:
        seq = sequence_from_dict(dict(gait.contact_sequence or {}))
    except ContactSequenceError as exc:
        raise StabilityError(f"contact_sequence: {exc}") from None
    model = gait.model
    swap = leg_swap(model).contacts
    phases = gait.phases
    if len(phases) != len(seq.phases):
        raise StabilityError(f"contact_sequence: {len(seq.phases)} phases, but the gait has "
                             f"{len(phases)}")
    pinned = [h.name for h in holds(model, seq.phases[0].held) if len(h.axes) == 2]
    if not pinned:
        raise StabilityError(f"contact_sequence.phases[0].held = {list(seq.phases[0].held)}: "
                             "the step must start with a point pinned on the ground (the "
                             "Poincare section holds it at the origin)")
    events: list[tuple[StepEvent, ...]] = []
    guards: dict[int, str] = {}  # phase index -> the point whose touchdown ends it
    recorded = {e.leg: e for e in gait.events}  # the gait's events, by the point they move
    for i, ev in enumerate(seq.events):
        after = seq.holds_after(i, swap)
        jumps = []
        if ev.touchdown:
            guards[i] = ev.touchdown[0]
            jumps.append(StepEvent("strike", ev.touchdown[0], after))
        for point in ev.release:
            impulse = recorded[point].impulses.get(point) if point in recorded else None
            magnitude = 0.0 if impulse is None or ev.touchdown else float(np.hypot(*impulse))
            jumps.append(StepEvent("liftoff", point, after, magnitude))
        events.append(tuple(jumps))
    if not guards:
        raise StabilityError("contact_sequence.events: no touchdown, so no guard ends a phase")

    def profile(i: int) -> PhaseProfile:
        ph = phases[i]
        return PhaseProfile(contacts=seq.phases[i].held,
                            duration=None if i in guards else ph.duration,
                            t=ph.t - ph.t[0], u=np.array(ph.u), q=np.array(ph.q),
                            qd=np.array(ph.qd), qdd=np.array(ph.qdd),
                            nominal_duration=ph.duration, guard=guards.get(i))

    return StepSpec(model=model, stance=pinned[0], swing=guards[min(guards)],
                    phases=tuple(profile(i) for i in range(len(phases))),
                    events=tuple(events), arm_distance=ARM_FRACTION * gait.step_length,
                    pd=pd, rtol=rtol, atol=rtol, section_holds=seq.phases[0].held)


def gait_start(gait: Gait) -> Array:
    """The gait's state at the start of single support, ``[q; qd]`` (2 nq,)."""
    return np.concatenate([gait.phases[0].q[0], gait.phases[0].qd[0]])


# -- the section -------------------------------------------------------------------------------

def tangent_basis(spec: StepSpec, y: Array) -> tuple[Array, Array]:
    """``(V (2nq, 2nq - r), C (r, 2nq))``: an orthonormal basis of the section's tangent
    space at ``y`` and the constraint Jacobian whose null space it is (``r`` = 4 for the
    stance tip pinned: its position and velocity)."""
    _, c = section_constraints(spec, y)
    _, s, vt = np.linalg.svd(c)
    if s[-1] < 1e-9 * s[0]:
        raise StabilityError(f"the section's constraints ({', '.join(spec.holds)} held) are "
                             "singular at the section state")
    return vt[c.shape[0]:].T, c


def project_to_section(spec: StepSpec, y: Array) -> Array:
    """The nearest state on the section: the base shifted so the stance tip is at the origin,
    the held points' velocities removed by least squares (``qd - J^+ J qd``; a point held
    along the normal only keeps its height: the shift is along the base's x, y)."""
    nq = spec.nq
    y = np.array(y, dtype=float)
    # the base moves by the stance point's (x, y)
    y[BASE_POSITION] -= np.asarray(contact_position(spec.model, y[:nq], spec.stance),
                                   float).ravel()
    jac = np.asarray(contact_jacobian(spec.model, y[:nq], list(spec.holds)), dtype=float)
    y[nq:] -= np.linalg.pinv(jac) @ (jac @ y[nq:])
    return y


def free_rotations(spec: StepSpec, states: list[Array]) -> list[tuple[str, Array]]:
    """Links whose absolute angle is decoupled at every state in ``states``: ``(link name,
    the q-direction (nq,) that turns that link alone)``."""
    model, nq = spec.model, spec.nq
    # Columns of t: x, y, then the rotation of each link alone (its children kept still).
    t = np.zeros((nq, nq))
    t[0, 0] = t[1, 1] = 1.0
    for k in range(len(model.links)):
        t[model.coordinate_of_link(k), 2 + k] = 1.0
        for c in range(len(model.links)):
            if model.parent_index(c) == k:
                t[model.coordinate_of_link(c), 2 + k] = -1.0
    s_q, _ = swap_matrices(model)
    b = np.array(actuation_rows(model, [c.name for c in model.contacts]), dtype=float)
    names = [c.name for c in model.contacts]
    out = []
    for k, link in enumerate(model.links):
        v = t[:, 2 + k]
        if not np.allclose(s_q @ v, v):
            continue
        free = not np.any(np.abs(t.T @ b)[2 + k] > 0.0)
        for y in states:
            q = y[:nq]
            m_abs = t.T @ np.asarray(crba(model, q), dtype=float) @ t
            g_abs = t.T @ np.asarray(gravity_forces(model, q), dtype=float)
            jac = np.asarray(contact_jacobian(model, q, names), dtype=float)
            scale = np.max(np.abs(m_abs))
            others = np.delete(m_abs[2 + k], 2 + k)
            free = free and bool(np.max(np.abs(others)) <= 1e-12 * scale
                                 and abs(g_abs[2 + k]) <= 1e-12 * np.max(np.abs(g_abs))
                                 and np.max(np.abs(jac @ v)) <= 1e-12)
        if free:
            out.append((link.name, v / np.linalg.norm(v)))
    return out


# -- the analysis ------------------------------------------------------------------------------

def floquet(spec: StepSpec, y: Array, *, check: bool = True, fd_step: float = FD_STEP,
            margin: float = 1e-3, about: About = "simulation") -> dict[str, Any]:
    """Monodromy, section restriction, removed directions and multipliers at ``y``
    (``about="gait"``: linearized about the reference trajectories, no finite differences)."""
    nq, n = spec.nq, 2 * spec.nq
    result = (reference_step(spec) if about == "gait"
              else simulate_step(spec, y, variational=True))
    assert result.monodromy is not None
    phi = result.monodromy
    basis, c = tangent_basis(spec, y)
    names = list(spec.model.coordinate_names)
    held = ", ".join(spec.holds)
    removed = [RemovedDirections(
        "stance tip position and velocity (x, y)" if spec.holds == (spec.stance,) else
        f"held points' positions and velocities ({held})",
        f"the section's constraints: the map holds {held} at rest on the ground "
        "(the stance point at the origin)", c.shape[0])]
    # Free rotations: an invariant subspace [v; 0], [0; v] removed by a quotient.
    s_cols = []
    for link, v in free_rotations(spec, [y, result.y_strike]):
        s_cols += [np.concatenate([v, np.zeros(nq)]), np.concatenate([np.zeros(nq), v])]
        removed.append(RemovedDirections(
            f"free rotation of link {link} (angle and rate)",
            "decoupled: no mass-matrix coupling, gravity moment, contact or actuator; the map "
            "is [[1, T], [0, 1]] on it", 2))
    notes = []
    if s_cols:
        s = np.linalg.qr(basis.T @ np.array(s_cols).T)[0]  # in tangent coordinates
        rest = np.linalg.svd(np.eye(basis.shape[1]) - s @ s.T)[0][:, :basis.shape[1] - s.shape[1]]
        q_full = np.hstack([s, rest])
        a = q_full.T @ (basis.T @ phi @ basis) @ q_full
        k = s.shape[1]
        leak = float(np.max(np.abs(a[k:, :k]), initial=0.0))
        notes.append(f"free rotations: invariant to {leak:.1e} (coupling out of the removed "
                     "subspace)")
        removed[-1] = replace(removed[-1], multipliers=tuple(np.linalg.eigvals(a[:k, :k])))
        reduced = a[k:, k:]
        basis = basis @ rest
    else:
        reduced = basis.T @ phi @ basis
    mult, vecs = np.linalg.eig(reduced)
    order = np.argsort(-np.abs(mult), kind="stable")
    mult, vecs = mult[order], vecs[:, order]
    radius = float(np.max(np.abs(mult))) if mult.size else 0.0
    verdict = ("stable" if radius < 1 - margin else "unstable" if radius > 1 + margin
               else "marginal")
    for i, m in enumerate(mult):
        if abs(m - 1.0) < UNIT_TOLERANCE:
            d = np.real(basis @ vecs[:, i])
            top = np.argsort(-np.abs(d))[:3]
            comp = ", ".join(f"{'q' if j < nq else 'qd'}:{names[j % nq]} {d[j]:+.2f}"
                             for j in top)
            notes.append(f"multiplier {m.real:.6f}{m.imag:+.1e}j is at 1: direction {comp}")
    if not any(abs(m - 1.0) < UNIT_TOLERANCE for m in mult):
        notes.append(f"no multiplier within {UNIT_TOLERANCE:g} of 1")
    f0 = phase_field(spec, spec.phases[0], 0.0, y)
    f_t = basis.T @ f0
    if np.linalg.norm(f_t) > 0:
        ratio = float(np.linalg.norm(reduced @ f_t) / np.linalg.norm(f_t))
        notes.append(f"flow direction at the section: |DP f| / |f| = {ratio:.3g} (0 for an "
                     "autonomous system: a shift along the orbit does not change the next "
                     "step's start)")
    fd_agreement = None
    if check and about == "simulation":
        full_basis, _ = tangent_basis(spec, y)
        fd = np.empty((n, full_basis.shape[1]))
        for j in range(full_basis.shape[1]):
            e = fd_step * full_basis[:, j]
            fd[:, j] = (step_map(spec, y + e) - step_map(spec, y - e)) / (2 * fd_step)
        var = phi @ full_basis
        fd_agreement = float(np.max(np.abs(fd - var)) / max(np.max(np.abs(var)), 1.0))
    return {"multipliers": mult, "radius": radius, "verdict": verdict, "removed": removed,
            "notes": notes, "monodromy": phi, "reduced": reduced, "basis": basis,
            "result": result, "fd_agreement": fd_agreement,
            "residual": float(np.max(np.abs(result.y_next - y)))}


def newton_fixed_point(spec: StepSpec, y0: Array, *, tol: float = 1e-8,
                       max_iter: int = 20) -> tuple[Array, int]:
    """A fixed point of the return map near ``y0`` by Newton's method on the section:
    ``dz = -lstsq(V^T Phi V - I, V^T (P(y) - y))``, ``y <- project(y + V dz)``. Returns
    ``(y*, iterations)``; raises :class:`StabilityError` if it does not converge (undamped: it
    needs a start near the fixed point)."""
    y = project_to_section(spec, y0)
    for it in range(max_iter):
        result = simulate_step(spec, y, variational=True)
        assert result.monodromy is not None
        r = result.y_next - y
        if np.max(np.abs(r)) < tol:
            return y, it
        basis, _ = tangent_basis(spec, y)
        a = basis.T @ result.monodromy @ basis - np.eye(basis.shape[1])
        dz = np.linalg.lstsq(a, -(basis.T @ r), rcond=1e-10)[0]
        y = project_to_section(spec, y + basis @ dz)
    raise StabilityError(f"Newton's method found no fixed point of the return map within "
                         f"{max_iter} iterations (last residual {np.max(np.abs(r)):.3g})")


def analyse_step(spec: StepSpec, y0: Array, *, fixed_point: Literal["start", "newton"] = "start",
                 check: bool = True, margin: float = 1e-3, about: About = "simulation",
                 fd_step: float = FD_STEP) -> StabilityReport:
    """:class:`StabilityReport` of the return map ``spec`` at ``y0`` or at the fixed point
    Newton's method finds from it; ``about="gait"`` linearizes about the reference
    trajectories of ``spec`` (a gait's knots) instead of the simulated step."""
    y0 = np.asarray(y0, dtype=float)
    if about == "gait":
        if fixed_point == "newton":
            raise StabilityError("fixed_point='newton' needs about='simulation'")
        start_residual = float(np.max(np.abs(reference_step(spec).y_next - y0)))
    else:
        start_residual = float(np.max(np.abs(step_map(spec, y0) - y0)))
    y = newton_fixed_point(spec, y0)[0] if fixed_point == "newton" else y0
    out = floquet(spec, y, check=check, margin=margin, about=about, fd_step=fd_step)
    result = out["result"]
    return StabilityReport(
        multipliers=out["multipliers"], spectral_radius=out["radius"], verdict=out["verdict"],
        margin=margin, removed=tuple(out["removed"]), notes=tuple(out["notes"]),
        fixed_point=("Newton fixed point" if fixed_point == "newton" else "gait start") + (
            " (linearized about the gait's knots)" if about == "gait" else ""),
        residual=out["residual"], start_residual=start_residual, state=y,
        step_time=result.step_time, monodromy=out["monodromy"],
        section_monodromy=out["reduced"], basis=out["basis"],
        fd_agreement=out["fd_agreement"],
        settings={"pd": None if spec.pd is None else list(spec.pd),
                  "pd_torques_bounded": False, "rtol": spec.rtol, "atol": spec.atol,
                  "margin": margin, "about": about,
                  "fd_step": fd_step if check and about == "simulation" else None,
                  "unit_tolerance": UNIT_TOLERANCE})


def gait_stability(gait: Gait, *, pd: tuple[float, float] | None = None,
                   fixed_point: Literal["start", "newton"] = "start", check: bool = True,
                   margin: float = 1e-3, rtol: float = 1e-10,
                   about: About = "simulation") -> StabilityReport:
    """Orbital stability of ``gait``: Floquet multipliers of its return map (module docstring).

    ``pd=(kp, kd)`` adds joint-space PD tracking of the gait's knots (N m/rad, N m s/rad;
    torques unbounded). ``fixed_point="newton"`` first finds the nearby fixed point of the
    simulated map; ``"start"`` analyses at the gait's own start state (its residual says how
    periodic the simulated gait is). ``check`` also computes the finite-difference monodromy.
    ``about="gait"`` linearizes about the gait's own (interpolated) knots instead of the
    simulated step: the multipliers of the orbit the optimizer found, meaningful when the
    open-loop simulation drifts far from it (no finite-difference check then).
    Raises :class:`StabilityError` for a failed gait or one whose simulated step has no heel
    strike.
    """
    spec = step_from_gait(gait, pd=pd, rtol=rtol)
    try:
        return analyse_step(spec, gait_start(gait), fixed_point=fixed_point, check=check,
                            margin=margin, about=about)
    except StepSimulationError as exc:
        raise StabilityError(f"the simulated step fails ({exc}); the open-loop replay of a "
                             "coarse gait can diverge before the heel strike: try PD tracking "
                             "(pd=(kp, kd), --pd KP,KD)") from None
