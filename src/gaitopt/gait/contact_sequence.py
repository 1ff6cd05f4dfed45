"""A gait as a contact sequence: phases that hold contact points, joined by events.

One step of a symmetric periodic gait is a list of phases run in order. Each phase names the
contact points held on the ground; event ``i`` ends phase ``i``:

* ``touchdown``: these points strike the ground (an inelastic impact: afterwards every point
  held in the next phase has zero velocity; the impulses act on all of them);
* ``release``: these points leave the ground, optionally with the liftoff impulse (magnitude
  ``P``, along the leg from the point toward its hip) while the others stay held.

An event may do both at once (the single-support gait: the front tip strikes and the rear tip
leaves at that instant). After the last event the legs swap roles (the mapping of the model's
:func:`~gaitopt.gait.gait_file.leg_swap_permutations`) and the gait moves on by one step length,
and the next step starts again with phase 0.

A held point stands still at its *anchor* on the ground: ``x = anchor * L`` (``L`` the step
length), ``y = 0``. Leg 1 stands at ``x = 0`` and leg 2 lands at ``x = L``. Phase durations
are fractions of the step time ``L / v``.

The three built-in sequences (:data:`SEQUENCES`) are instances of this one mechanism:

* ``walk`` (the paper's): single support on tip 1 -> tip 2 touches down (tip 1 held) ->
  double support -> tip 1 released with the liftoff impulse;
* ``walk-single-support``: single support on tip 1 -> tip 2 touches down and tip 1 releases;
* ``run``: stance on tip 1 -> tip 1 released (no impulse) -> flight -> tip 2 touches down.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from gaitopt.robot.model import RobotModel


class ContactSequenceError(ValueError):
    """A contact sequence is inconsistent with itself or with the model."""


@dataclass(frozen=True)
class PhaseSpec:
    """One phase: its name, the contact points held, and its share of the step time."""

    name: str
    held: tuple[str, ...]
    fraction: float


@dataclass(frozen=True)
class EventSpec:
    """The event that ends a phase: points that touch down and points released.

    ``impulse``: the released point (exactly one) gets the liftoff impulse ``P``."""

    name: str
    touchdown: tuple[str, ...] = ()
    release: tuple[str, ...] = ()
    impulse: bool = False


@dataclass(frozen=True)
class ContactSequence:
    """Phases and the events that end them (``events[i]`` ends ``phases[i]``), with the
    ground anchor of each contact point (``x = anchor * L``, see the module docstring)."""

    name: str
    phases: tuple[PhaseSpec, ...]
    events: tuple[EventSpec, ...]
    anchors: tuple[tuple[str, float], ...]

    def anchor(self, contact: str) -> float:
        """The anchor of ``contact`` (its ground x in step lengths)."""
        return dict(self.anchors)[contact]

    def held_after(self, i: int) -> tuple[str, ...]:
        """The points held just after event ``i`` (before any leg swap)."""
        ev, held = self.events[i], self.phases[i].held
        kept = tuple(c for c in held if c not in ev.release)
        return kept + tuple(c for c in ev.touchdown if c not in kept)

    def to_dict(self) -> dict[str, object]:
        """Plain data for the gait file."""
        return {
            "name": self.name,
            "phases": [{"name": p.name, "held": list(p.held), "fraction": p.fraction}
                       for p in self.phases],
            "events": [{"name": e.name, "touchdown": list(e.touchdown),
                        "release": list(e.release), "impulse": e.impulse}
                       for e in self.events],
            "anchors": {c: a for c, a in self.anchors},
        }


def walking_sequence(model: RobotModel, single_support_fraction: float, *,
                     impulse: bool) -> ContactSequence:
    """The paper's walk (``single_support_fraction < 1``) or the single-support walk (``= 1``)
    on the model's first two contact points (leg 1, leg 2)."""
    c1, c2 = _two_contacts(model)
    anchors = ((c1, 0.0), (c2, 1.0))
    if single_support_fraction >= 1.0:
        return ContactSequence(
            "walk-single-support",
            (PhaseSpec("single_support", (c1,), 1.0),),
            (EventSpec("heel_strike", touchdown=(c2,), release=(c1,)),),
            anchors)
    f = single_support_fraction
    return ContactSequence(
        "walk",
        (PhaseSpec("single_support", (c1,), f), PhaseSpec("double_support", (c1, c2), 1.0 - f)),
        (EventSpec("heel_strike", touchdown=(c2,)),
         EventSpec("liftoff", release=(c1,), impulse=impulse)),
        anchors)


def running_sequence(model: RobotModel, stance_fraction: float) -> ContactSequence:
    """A run: stance on leg 1 for ``stance_fraction`` of the step, then flight; leg 2 lands
    one step length ahead."""
    c1, c2 = _two_contacts(model)
    f = stance_fraction
    return ContactSequence(
        "run",
        (PhaseSpec("stance", (c1,), f), PhaseSpec("flight", (), 1.0 - f)),
        (EventSpec("toe_off", release=(c1,)), EventSpec("touchdown", touchdown=(c2,))),
        ((c1, 0.0), (c2, 1.0)))


def _two_contacts(model: RobotModel) -> tuple[str, str]:
    if len(model.contacts) < 2:
        raise ContactSequenceError(
            f"model {model.name!r}: a walking sequence needs two contact points (one per "
            f"leg); it has {len(model.contacts)}")
    return model.contacts[0].name, model.contacts[1].name


def check_sequence(model: RobotModel, seq: ContactSequence,
                   contact_swap: dict[str, str]) -> None:
    """Raise :class:`ContactSequenceError` unless ``seq`` is consistent: every named point is
    a contact of ``model`` with an anchor, events match the phases they join, fractions are
    positive and sum to 1, and the last event leads (after the leg swap) into phase 0."""
    names = {c.name for c in model.contacts}
    if not seq.phases or len(seq.events) != len(seq.phases):
        raise ContactSequenceError(f"sequence {seq.name!r}: needs one event per phase")
    anchors = dict(seq.anchors)
    for ph in seq.phases:
        for c in ph.held:
            if c not in names:
                raise ContactSequenceError(f"sequence {seq.name!r}: phase {ph.name!r} holds "
                                           f"{c!r}, not a contact of model {model.name!r}")
            if c not in anchors:
                raise ContactSequenceError(f"sequence {seq.name!r}: contact {c!r} has no "
                                           "anchor")
        if not ph.fraction > 0.0:
            raise ContactSequenceError(f"sequence {seq.name!r}: phase {ph.name!r} fraction "
                                       f"{ph.fraction:g} must be > 0")
    total = sum(ph.fraction for ph in seq.phases)
    if abs(total - 1.0) > 1e-9:
        raise ContactSequenceError(f"sequence {seq.name!r}: phase fractions sum to "
                                   f"{total:g}, not 1")
    for i, ev in enumerate(seq.events):
        held = seq.phases[i].held
        for c in ev.release:
            if c not in held:
                raise ContactSequenceError(f"sequence {seq.name!r}: event {ev.name!r} "
                                           f"releases {c!r}, which is not held")
        for c in ev.touchdown:
            if c in held or c not in anchors:
                raise ContactSequenceError(f"sequence {seq.name!r}: event {ev.name!r} "
                                           f"touches down {c!r}, which is held or unanchored")
        if ev.impulse and len(ev.release) != 1:
            raise ContactSequenceError(f"sequence {seq.name!r}: event {ev.name!r} has an "
                                       "impulse but does not release exactly one point")
        after = set(seq.held_after(i))
        nxt = seq.phases[(i + 1) % len(seq.phases)].held
        if i == len(seq.events) - 1:
            after = {contact_swap.get(c, c) for c in after}
        if after != set(nxt):
            raise ContactSequenceError(
                f"sequence {seq.name!r}: after event {ev.name!r} the points "
                f"{sorted(after)} are held, but the next phase holds {sorted(nxt)}")


def phase_index(seq: ContactSequence, name: str) -> int:
    """Position of the phase called ``name``."""
    for i, ph in enumerate(seq.phases):
        if ph.name == name:
            return i
    raise KeyError(name)


def sequence_phase_names(seq: ContactSequence) -> Sequence[str]:
    return tuple(ph.name for ph in seq.phases)
