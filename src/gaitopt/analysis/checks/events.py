"""Checks of the events (heel strike, liftoff) and of periodicity, in full coordinates.

For each event at the end of phase i (its time equals that phase's last knot):

* ``events.continuity``: the event time is a phase boundary, ``qd_before`` equals phase i's
  last ``qd``; after it, the next phase starts at the same ``q`` with ``qd = qd_after``;
* ``events.maps`` / ``events.impulses``: ``qd_after`` and the impulses equal the maps of
  :mod:`gaitopt.dynamics.functions` applied to ``(q, qd_before)``: a heel strike is the
  inelastic impact of the contacts held in the following phase (after the step's last phase,
  the first phase's contacts with the legs relabelled: ``tip_1`` -> ``tip_2``); a liftoff
  applies the liftoff impulse (``parameters.liftoff_impulse``) on the lifting tip while the
  other contacts held before it stay;
* ``events.periodicity``: the state after the last event, legs swapped (``S_q q``, ``S_q qd``:
  :func:`~gaitopt.robot.symmetry.swap_matrices`) and shifted back one step length (a
  stride's: not swapped, shifted back two step lengths; :func:`period_maps`),
  equals the first knot; ``events.periodic_controls`` the same for the controls of the
  actuators acting at both ends, if the gait was solved with periodic controls (and the
  paper's control model: with ``control_model = "jumps"`` the torques may jump at the events).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.checks.check import Check, Worst
from gaitopt.dynamics.functions import impact_function, liftoff_function
from gaitopt.dynamics.tree import hold_name
from gaitopt.gait.formulations.full.physics import per_point
from gaitopt.gait.record.file import Gait, GaitEvent
from gaitopt.gait.sequence.contact_sequence import ContactSequence, EventSpec, sequence_from_dict
from gaitopt.robot.symmetry import swap_matrices, swap_names

Array = NDArray[np.float64]

#: Events that are touchdowns (impacts), and releases with the liftoff impulse; any other
#: event (a run's ``toe_off``) releases its point with the velocities unchanged.
TOUCHDOWNS = frozenset({"heel_strike", "touchdown"})
IMPULSE_RELEASES = frozenset({"liftoff"})


def _phase_ending_at(gait: Gait, t: float) -> int | None:
    """Index of the last phase whose end time is ``t`` (within 1e-9 s)."""
    ends = [i for i, ph in enumerate(gait.phases) if abs(ph.t[-1] - t) <= 1e-9]
    return ends[-1] if ends else None


def period_maps(gait: Gait) -> tuple[Array, Array, dict[str, str]]:
    """``(S_q, S_u, names)``: the map from the end of the gait's period to its start, of the
    coordinates (nq, nq), the actuators (nu, nu) and the names of points, joints and links:
    the leg swap (:func:`~gaitopt.robot.symmetry.swap_matrices`,
    :func:`~gaitopt.robot.symmetry.swap_names`) for one step, the identity for a stride
    (:attr:`Gait.period_steps` 2)."""
    model = gait.model
    if gait.period_steps == 1:
        s_q, s_u = swap_matrices(model)
        return s_q, s_u, swap_names(model)
    return np.eye(model.nq), np.eye(model.nu), {}


def _held_after_strike(gait: Gait, i: int, leg: str) -> tuple[str, ...]:
    if i + 1 < len(gait.phases):
        return tuple(gait.phases[i + 1].contacts)
    names = period_maps(gait)[2]
    relabelled = tuple(names.get(c, c) for c in gait.phases[0].contacts)
    return relabelled if leg in relabelled else (leg,)


def _apply(gait: Gait, event: GaitEvent, q: Array, held: tuple[str, ...], i: int
           ) -> tuple[Array, dict[str, Array], tuple[str, ...]]:
    """``(qd_after, impulses, contacts held after)`` of ``event`` (at the end of phase ``i``)
    from ``(q, qd_before)``. With the gait's contact sequence, the event's kind and the hold
    specs after it come from there (:meth:`ContactSequence.holds_after`); impulses are
    ``(2,)`` per point (:func:`gaitopt.gait.formulations.full.physics.per_point`)."""
    model = gait.model
    spec = _sequence_event(gait, i, event)
    if spec is not None:
        seq, ev = spec
        after = seq.holds_after(i, period_maps(gait)[2])
        touchdown, impulse = bool(ev.touchdown), ev.impulse
    else:
        touchdown, impulse = event.name in TOUCHDOWNS, event.name in IMPULSE_RELEASES
        after = held if touchdown else tuple(c for c in held if c != event.leg)
    names = tuple(hold_name(c) for c in after)
    if touchdown:
        qd, imp = impact_function(model, after)(q, event.qd_before)
        impulses = {c: np.asarray(v, dtype=float).ravel()
                    for c, v in per_point(after, np.asarray(imp, dtype=float).ravel()).items()}
        return np.asarray(qd, dtype=float).ravel(), impulses, names
    if not impulse:  # a release without impulse: velocities continue
        return np.array(event.qd_before, dtype=float), {}, names
    p = gait.parameters["liftoff_impulse"]
    qd, lifting, on_held = liftoff_function(model, event.leg, list(after))(q, event.qd_before, p)
    impulses = {event.leg: np.asarray(lifting, dtype=float).ravel()}
    if after:
        impulses |= {c: np.asarray(v, dtype=float).ravel() for c, v in
                     per_point(after, np.asarray(on_held, dtype=float).ravel()).items()}
    return np.asarray(qd, dtype=float).ravel(), impulses, names


def _sequence_event(gait: Gait, i: int, event: GaitEvent) -> tuple[ContactSequence,
                                                                    EventSpec] | None:
    """The gait's contact sequence and its event ``i``, when the file has a sequence whose
    event ``i`` is ``event`` (same name)."""
    if gait.contact_sequence is None:
        return None
    seq = sequence_from_dict(dict(gait.contact_sequence))
    if i < len(seq.events) and seq.events[i].name == event.name:
        return seq, seq.events[i]
    return None


def _events_of_phase(gait: Gait, i: int) -> list[GaitEvent]:
    """The events at the end of phase i in order (a heel strike before a liftoff)."""
    return sorted((e for e in gait.events if _phase_ending_at(gait, e.t) == i),
                  key=lambda e: (e.t, e.name not in TOUCHDOWNS))


def event_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    """The checks listed in the module docstring."""
    keys = ("events.continuity", "events.maps", "events.impulses")
    worst = dict.fromkeys(keys, Worst())
    for j, e in enumerate(gait.events):
        if _phase_ending_at(gait, e.t) is None:
            worst["events.continuity"] = Worst(np.inf, f"events[{j}] ({e.name}): t = {e.t:g} s "
                                               "is no phase's end")
    q, qd = gait.phases[-1].q[-1], gait.phases[-1].qd[-1]
    for i, ph in enumerate(gait.phases):
        held = tuple(ph.contacts)
        q, qd = ph.q[-1], ph.qd[-1]
        where = f"phases[{i}] ({ph.name}) end"
        for e in _events_of_phase(gait, i):
            where = f"events[{gait.events.index(e)}] ({e.name})"
            worst["events.continuity"] = worst["events.continuity"].update(
                float(np.max(np.abs(e.qd_before - qd))), where)
            if e.name in TOUCHDOWNS:
                held = _held_after_strike(gait, i, e.leg)
            qd_after, impulses, held = _apply(gait, e, q, held, i)
            worst["events.maps"] = worst["events.maps"].update(
                float(np.max(np.abs(qd_after - e.qd_after))), where)
            zero = np.zeros(2)
            imp_err = max(float(np.max(np.abs(impulses.get(c, zero) - e.impulses.get(c, zero))))
                          for c in set(impulses) | set(e.impulses))
            worst["events.impulses"] = worst["events.impulses"].update(imp_err, where)
            qd = e.qd_after
        if i + 1 < len(gait.phases):
            nxt = gait.phases[i + 1]
            gap = max(float(np.max(np.abs(nxt.q[0] - q))), float(np.max(np.abs(nxt.qd[0] - qd))),
                      abs(float(nxt.t[0] - ph.t[-1])))
            worst["events.continuity"] = worst["events.continuity"].update(
                gap, f"{where} -> phases[{i + 1}] ({nxt.name}) knot 0")
    checks = [worst[k].check(k, lim) for k in keys]
    return checks + _periodicity_checks(gait, q, qd, lim)


def _periodicity_checks(gait: Gait, q_end: Array, qd_end: Array, lim: dict[str, float]
                        ) -> list[Check]:
    model = gait.model
    s_q, s_u, _ = period_maps(gait)
    first, last = gait.phases[0], gait.phases[-1]
    q_next = s_q @ q_end
    q_next[model.coordinate_names.index("x")] -= gait.period_steps * gait.step_length
    err = np.concatenate([np.abs(q_next - first.q[0]), np.abs(s_q @ qd_end - first.qd[0])])
    k = int(np.argmax(err))
    names = model.coordinate_names
    label = names[k] if k < len(names) else f"{names[k - len(names)]}_rate"
    checks = [Check("events.periodicity", float(err[k]), lim["events.periodicity"],
                    f"{label}")]
    if (gait.options.get("periodic_controls", True)
            and gait.options.get("control_model", "paper") == "paper"):
        u_next = s_u @ last.u[-1]
        active = np.abs(first.u[0]) > 0  # actuators that act at the start of the step
        both = active & (np.abs(u_next) > 0)
        diff = np.where(both, np.abs(u_next - first.u[0]), 0.0)
        j = int(np.argmax(diff))
        checks.append(Check("events.periodic_controls", float(diff[j]),
                            lim["events.periodic_controls"], model.actuators[j].name))
    return checks
