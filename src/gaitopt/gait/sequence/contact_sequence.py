"""A gait as a contact sequence: phases that hold contact points, joined by events.

One step of a symmetric periodic gait is a list of phases run in order. Each phase names the
contact points held on the ground; event ``i`` ends phase ``i``:

* ``touchdown``: these points strike the ground (an inelastic impact: afterwards every point
  held in the next phase has zero velocity; the impulses act on all of them);
* ``release``: these points leave the ground, optionally with the liftoff impulse (magnitude
  ``P``, along the leg from the point toward its hip) while the others stay held.

An event may do both at once (the single-support gait: the front tip strikes and the rear tip
leaves at that instant). After the last event the legs swap roles (the mapping of the model's
:func:`~gaitopt.robot.symmetry.swap_matrices`) and the gait moves on by one step length,
and the next step starts again with phase 0.

A held point stands still at its *anchor* on the ground: ``x = anchor * L + offset`` (``L``
the step length, ``offset`` in metres, 0 unless given), ``y = 0``. Leg 1 stands at ``x = 0``
and leg 2 lands at ``x = L``. Phase durations are fractions of the step time ``L / v``: given
(fixed), or free within bounds (:attr:`PhaseSpec.bounds`; the fraction is then a first guess and
the solve chooses it, :mod:`gaitopt.gait.sequence.phase_fractions`).

A phase holds each point by a *hold spec* (:func:`gaitopt.dynamics.tree.holds`): ``name``
pins it (x and y), ``name:y`` holds it along the ground normal only. A flat foot is its heel
pinned and its toe held by ``toe:y``: pinning both would state the foot's three constraints
four times (a singular contact problem). A normal-only hold needs no anchor. A point may change
how it is held at an event (the toe of a flat foot becomes pinned when the heel rises): the
foot stands still before the event, so no impact is needed.

The built-in sequences (:mod:`gaitopt.gait.sequence.builtin`) are instances of this one
mechanism:

* ``walk`` (the paper's): single support on tip 1 -> tip 2 touches down (tip 1 held) ->
  double support -> tip 1 released with the liftoff impulse;
* ``walk-single-support``: single support on tip 1 -> tip 2 touches down and tip 1 releases;
* ``run``: stance on tip 1 -> tip 1 released (no impulse) -> flight -> tip 2 touches down;
* ``heel-toe`` (feet with heel and toe points): foot 1 flat -> heel 1 rises -> toe 1 rolls ->
  heel 2 strikes -> double support on toe 1 and heel 2 -> toe 1 leaves (optional impulse) ->
  foot 2 rolls on its heel -> toe 2 strikes (foot flat).

A user gives any other sequence as data (:func:`sequence_from_dict`, the ``contact_sequence``
section of a YAML file; docs/formulations.md).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.tree import hold_name, holds
from gaitopt.gait.sequence.knots import knots_in_order
from gaitopt.robot.model import RobotModel


class ContactSequenceError(ValueError):
    """A contact sequence is inconsistent with itself or with the model."""


@dataclass(frozen=True)
class PhaseSpec:
    """One phase: its name, the contact points held, and its share of the step time.

    ``bounds``: ``None`` (the share is ``fraction``) or ``(lower, upper)``, ``0 < lower <=
    fraction <= upper <= 1``: the share is free within them and ``fraction`` is its first
    guess."""

    name: str
    held: tuple[str, ...]
    fraction: float
    bounds: tuple[float, float] | None = None
    #: Where this phase's points stand, when not at the sequence's anchors and offsets (the
    #: second step of a stride, :func:`stride_sequence`): contact -> step lengths, and m.
    anchors: tuple[tuple[str, float], ...] | None = None
    offsets: tuple[tuple[str, float], ...] | None = None

    @property
    def free(self) -> bool:
        """Whether the share is a decision (it has bounds)."""
        return self.bounds is not None

    def fraction_data(self) -> float | dict[str, float]:
        """The ``fraction`` field of the plain data: a number, or ``{guess, min, max}``."""
        if self.bounds is None:
            return self.fraction
        return {"guess": self.fraction, "min": self.bounds[0], "max": self.bounds[1]}


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
    ground anchor of each contact point (``x = anchor * L``, see the module docstring).

    ``steps``: 1, one step of a symmetric gait (after the last event the legs swap and ``x``
    moves on by ``L``), or 2, a stride (:func:`stride_sequence`: two steps, leg 1's then
    leg 2's, and after the last event no swap: ``x`` moves on by ``2 L``)."""

    name: str
    phases: tuple[PhaseSpec, ...]
    events: tuple[EventSpec, ...]
    anchors: tuple[tuple[str, float], ...]
    #: Ground x offsets (m) added to ``anchor * L``; points not listed have none.
    offsets: tuple[tuple[str, float], ...] = ()
    steps: int = 1

    def _anchors(self, phase: int | None) -> dict[str, float]:
        own = None if phase is None else self.phases[phase].anchors
        return dict(self.anchors if own is None else own)

    def anchored(self, phase: int | None = None) -> set[str]:
        """The contacts with an anchor (in phase ``phase``, else the sequence's)."""
        return set(self._anchors(phase))

    def anchor(self, contact: str, phase: int | None = None) -> float:
        """The anchor of ``contact`` (its ground x in step lengths) in phase ``phase`` (its
        own anchors if it has some, else the sequence's)."""
        return self._anchors(phase)[hold_name(contact)]

    def offset(self, contact: str, phase: int | None = None) -> float:
        """The ground x offset (m) of ``contact``'s anchor (in phase ``phase``)."""
        own = None if phase is None else self.phases[phase].offsets
        return dict(self.offsets if own is None else own).get(hold_name(contact), 0.0)

    def ground_x(self, contact: str, step_length: Any, phase: int | None = None) -> Any:
        """Where ``contact`` is held on the ground in phase ``phase``: ``anchor * L +
        offset`` (m). A point that touches down at the end of phase ``i`` lands at phase
        ``i``'s anchor for it."""
        return self.anchor(contact, phase) * step_length + self.offset(contact, phase)

    def period_contacts(self, contact_swap: Mapping[str, str]) -> Mapping[str, str]:
        """The renaming of the contacts from the end of the sequence to its start: the leg
        swap for one step, none (every name itself) for a stride."""
        if self.steps == 1:
            return contact_swap
        return {c: c for c in contact_swap}

    def held_after(self, i: int) -> tuple[str, ...]:
        """The names of the points held just after event ``i`` (before any leg swap)."""
        ev, held = self.events[i], [hold_name(c) for c in self.phases[i].held]
        kept = tuple(c for c in held if c not in ev.release)
        return kept + tuple(c for c in ev.touchdown if c not in kept)

    def holds_after(self, i: int, contact_swap: Mapping[str, str]) -> tuple[str, ...]:
        """The hold specs in force just after event ``i``: those of the next phase, in this
        step's names (after the last event, mapped back through the leg swap)."""
        nxt = self.phases[(i + 1) % len(self.phases)].held
        if i < len(self.events) - 1:
            return nxt
        return tuple(swap_spec(c, self.period_contacts(contact_swap)) for c in nxt)

    def to_dict(self) -> dict[str, Any]:
        """Plain data for the gait file."""
        def phase(p: PhaseSpec) -> dict[str, Any]:
            own = {k: dict(v) for k, v in (("anchors", p.anchors), ("offsets", p.offsets))
                   if v is not None}
            return {"name": p.name, "held": list(p.held), "fraction": p.fraction_data()} | own

        return {
            "name": self.name,
            "phases": [phase(p) for p in self.phases],
            "events": [{"name": e.name, "touchdown": list(e.touchdown),
                        "release": list(e.release), "impulse": e.impulse}
                       for e in self.events],
            "anchors": {c: a for c, a in self.anchors},
        } | ({"offsets": {c: b for c, b in self.offsets}} if self.offsets else {}) | (
            {"steps": self.steps} if self.steps != 1 else {})


def phase_holds(sequence: Mapping[str, Any] | None, i: int, contacts: Sequence[str]
                ) -> tuple[str, ...]:
    """The hold specs of phase ``i`` of a gait file: from its ``contact_sequence`` when it has
    one (and its phase ``i`` holds the points ``contacts``), else the contact names (pins)."""
    if sequence is not None:
        phases = sequence.get("phases", [])
        if i < len(phases):
            held = tuple(str(c) for c in phases[i].get("held", ()))
            if [hold_name(c) for c in held] == list(contacts):
                return held
    return tuple(contacts)


def phase_knots(seq: ContactSequence, knots: Sequence[int] | Mapping[str, int]
                ) -> tuple[int, ...]:
    """Knots of each phase from the ``knots`` option (:mod:`gaitopt.gait.sequence.knots`).

    ``knots = (first, others)``: a one-phase sequence takes ``first``; longer ones give phase
    0 ``first`` knots and every other phase at least ``others``, more when the density of
    phase 0 (intervals per share of the step) asks for more, so that long phases are not
    coarser than phase 0: phase ``i`` of share ``f_i`` gets ``max(others, 1 + ceil((first -
    1) f_i / f_0))``. The paper's walk (``f_0 = 0.85``) keeps ``(first, others)`` (its double
    support needs 4 of 6 knots); a run's flight of 65 % of the step after a stance of 35 %
    gets 1 + 28 knots, not 6 (docs/running.md, "Knots follow the shares"). One count per
    phase of the step, or a mapping phase name -> count naming every phase of the step
    (:func:`~gaitopt.gait.sequence.knots.knots_in_order`): those counts as they are. A
    stride's steps get the knots of one step each (its second step those of the first: like
    with like against the one-step problem), when its phases split into two steps of as many
    phases (a stride written by hand may not: then the rules above on all its phases).

    Raises:
        KnotsError: a mapping names a phase the step lacks or leaves one out.
    """
    n = len(seq.phases)
    repeats = seq.steps if n % seq.steps == 0 else 1
    step = seq.phases[:n // repeats]
    if isinstance(knots, Mapping):
        return knots_in_order(knots, [ph.name for ph in step]) * repeats
    if len(knots) == len(step) > 2:
        return tuple(int(k) for k in knots) * repeats
    first, others = int(knots[0]), int(knots[min(1, len(knots) - 1)])
    counts: tuple[int, ...]
    if len(step) == 1:
        counts = (first,)
    else:
        density = (first - 1) / step[0].fraction
        counts = (first,) + tuple(max(others, 1 + math.ceil(density * ph.fraction - 1e-9))
                                  for ph in step[1:])
    return counts * repeats


def swap_spec(spec: str, contact_swap: Mapping[str, str]) -> str:
    """A hold spec with its contact renamed by the leg swap (the axes kept)."""
    name, sep, axes = spec.partition(":")
    return contact_swap.get(name, name) + sep + axes


def sequence_from_dict(data: Any, where: str = "contact_sequence") -> ContactSequence:
    """A sequence from plain data (the form :meth:`ContactSequence.to_dict` writes, as in a
    YAML file): ``name``, ``phases`` (``name``, ``held``, ``fraction``: a number, or
    ``{guess, min, max}`` for a free one; optional ``anchors`` and ``offsets`` of its own),
    ``events`` (``name``, optional ``touchdown``, ``release``, ``impulse``), ``anchors``
    (contact -> step lengths), optional ``offsets`` (contact -> m), optional ``steps`` (1,
    or 2 for a stride). Check it against a model with :func:`check_sequence`."""
    def fail(field: str, value: Any, expected: str) -> ContactSequenceError:
        return ContactSequenceError(f"{where}.{field} = {value!r}: {expected}")

    def mapping(field: str, value: Any, keys: tuple[str, ...], required: tuple[str, ...]
                ) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise fail(field, value, "must be a mapping")
        extra = sorted(set(value) - set(keys))
        if extra:
            raise fail(field, value, f"unknown keys {extra} (allowed: {', '.join(keys)})")
        missing = [k for k in required if k not in value]
        if missing:
            raise fail(field, value, f"missing {', '.join(missing)}")
        return value

    def names(field: str, value: Any) -> tuple[str, ...]:
        if not isinstance(value, list | tuple) or not all(isinstance(v, str) for v in value):
            raise fail(field, value, "must be a list of contact names")
        return tuple(value)

    def number(field: str, value: Any) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise fail(field, value, "must be a number")
        return float(value)

    def share(field: str, value: Any) -> tuple[float, tuple[float, float] | None]:
        if not isinstance(value, dict):
            return number(field, value), None
        e = mapping(field, value, ("guess", "min", "max"), ("guess", "min", "max"))
        lo, guess, hi = (number(f"{field}.{k}", e[k]) for k in ("min", "guess", "max"))
        if not 0.0 < lo <= guess <= hi <= 1.0:
            raise fail(field, value, "needs 0 < min <= guess <= max <= 1")
        return guess, (lo, hi)

    def points(field: str, value: Any) -> tuple[tuple[str, float], ...]:
        if not isinstance(value, dict):
            raise fail(field, value, "must be a mapping of contact names to numbers")
        return tuple((str(c), number(f"{field}.{c}", a)) for c, a in value.items())

    top = mapping("", data, ("name", "phases", "events", "anchors", "offsets", "steps"),
                  ("phases", "events", "anchors"))
    steps = top.get("steps", 1)
    if steps not in (1, 2) or isinstance(steps, bool):
        raise fail("steps", steps, "must be 1 (one step, legs swapped after it) or 2 (a "
                                   "stride: two steps, no swap)")
    if not isinstance(top["phases"], list) or not top["phases"]:
        raise fail("phases", top["phases"], "must be a non-empty list")
    if not isinstance(top["events"], list):
        raise fail("events", top["events"], "must be a list (one event per phase)")
    phases = []
    for k, ph in enumerate(top["phases"]):
        e = mapping(f"phases[{k}]", ph, ("name", "held", "fraction", "anchors", "offsets"),
                    ("name", "held", "fraction"))
        fraction, bounds = share(f"phases[{k}].fraction", e["fraction"])
        own = {key: points(f"phases[{k}].{key}", e[key]) if key in e else None
               for key in ("anchors", "offsets")}
        phases.append(PhaseSpec(str(e["name"]), names(f"phases[{k}].held", e["held"]),
                                fraction, bounds, **own))
    events = []
    for k, ev in enumerate(top["events"]):
        e = mapping(f"events[{k}]", ev, ("name", "touchdown", "release", "impulse"),
                    ("name",))
        if not isinstance(e.get("impulse", False), bool):
            raise fail(f"events[{k}].impulse", e["impulse"], "must be true or false")
        events.append(EventSpec(str(e["name"]),
                                names(f"events[{k}].touchdown", e.get("touchdown", [])),
                                names(f"events[{k}].release", e.get("release", [])),
                                bool(e.get("impulse", False))))
    return ContactSequence(
        str(top.get("name", "custom")), tuple(phases), tuple(events),
        points("anchors", top["anchors"]), points("offsets", top.get("offsets", {}) or {}),
        int(steps))


def check_sequence(model: RobotModel, seq: ContactSequence,
                   contact_swap: dict[str, str]) -> None:
    """Raise :class:`ContactSequenceError` unless ``seq`` is consistent: every named point is
    a contact of ``model`` with an anchor, events match the phases they join, fractions (the
    first guesses of free ones) are positive, within their bounds and sum to 1, and the last
    event leads (after the leg swap) into phase 0."""
    names = {c.name for c in model.contacts}
    if not seq.phases or len(seq.events) != len(seq.phases):
        raise ContactSequenceError(f"sequence {seq.name!r}: needs one event per phase")
    if len({ph.name for ph in seq.phases}) != len(seq.phases):
        raise ContactSequenceError(f"sequence {seq.name!r}: phase names must be distinct")
    placed = [c for c, _ in seq.anchors + seq.offsets]
    for ph in seq.phases:
        placed += [c for c, _ in (ph.anchors or ()) + (ph.offsets or ())]
    for c in placed:
        if c not in names:
            raise ContactSequenceError(f"sequence {seq.name!r}: anchor of {c!r}, not a "
                                       f"contact of model {model.name!r}")
    for i_ph, ph in enumerate(seq.phases):
        anchors = seq.anchored(i_ph)
        for spec in ph.held:
            c = hold_name(spec)
            if c not in names:
                raise ContactSequenceError(f"sequence {seq.name!r}: phase {ph.name!r} holds "
                                           f"{c!r}, not a contact of model {model.name!r}")
            try:
                (hold,) = holds(model, (spec,), f"phase {ph.name!r}")
            except ValueError as exc:
                raise ContactSequenceError(f"sequence {seq.name!r}: {exc}") from None
            if 0 in hold.axes and c not in anchors:
                raise ContactSequenceError(f"sequence {seq.name!r}: contact {c!r} has no "
                                           "anchor")
        held_names = [hold_name(c) for c in ph.held]
        if len(set(held_names)) != len(held_names):
            raise ContactSequenceError(f"sequence {seq.name!r}: phase {ph.name!r} holds a "
                                       "point twice")
        if not ph.fraction > 0.0:
            raise ContactSequenceError(f"sequence {seq.name!r}: phase {ph.name!r} fraction "
                                       f"{ph.fraction:g} must be > 0")
        if ph.bounds is not None and not 0.0 < ph.bounds[0] <= ph.fraction <= ph.bounds[1] \
                <= 1.0:
            raise ContactSequenceError(
                f"sequence {seq.name!r}: phase {ph.name!r} fraction {ph.fraction:g} with "
                f"bounds [{ph.bounds[0]:g}, {ph.bounds[1]:g}]: needs 0 < min <= guess <= "
                "max <= 1")
    total = sum(ph.fraction for ph in seq.phases)
    free = [i for i, ph in enumerate(seq.phases) if ph.free]
    if abs(total - 1.0) > 1e-9:
        raise ContactSequenceError(f"sequence {seq.name!r}: phase fractions "
                                   f"{'(first guesses) ' if free else ''}sum to "
                                   f"{total:g}, not 1")
    if len(free) == 1:
        raise ContactSequenceError(
            f"sequence {seq.name!r}: phase {seq.phases[free[0]].name!r} is the only one with "
            "free fraction bounds; with every other share fixed its share is fixed too (give "
            "bounds to at least two phases)")
    for i, ev in enumerate(seq.events):
        held = [hold_name(c) for c in seq.phases[i].held]
        for c in ev.release:
            if c not in held:
                raise ContactSequenceError(f"sequence {seq.name!r}: event {ev.name!r} "
                                           f"releases {c!r}, which is not held")
        for c in ev.touchdown:
            if c in held or c not in names:
                raise ContactSequenceError(f"sequence {seq.name!r}: event {ev.name!r} "
                                           f"touches down {c!r}, which is held or not a "
                                           "contact of the model")
        if ev.impulse and len(ev.release) != 1:
            raise ContactSequenceError(f"sequence {seq.name!r}: event {ev.name!r} has an "
                                       "impulse but does not release exactly one point")
        after = set(seq.held_after(i))
        nxt = [hold_name(c) for c in seq.phases[(i + 1) % len(seq.phases)].held]
        if i == len(seq.events) - 1:
            period = seq.period_contacts(contact_swap)
            after = {period.get(c, c) for c in after}
        if after != set(nxt):
            raise ContactSequenceError(
                f"sequence {seq.name!r}: after event {ev.name!r} the points "
                f"{sorted(after)} are held, but the next phase holds {sorted(nxt)}")


#: Suffix of the names of the second step's phases and events in a stride.
SECOND_STEP = "_2"


def stride_sequence(seq: ContactSequence, pairing: Mapping[str, str]) -> ContactSequence:
    """Two steps of ``seq`` as one period without symmetry (``steps = 2``): leg 1's step as
    ``seq`` states it, then the same step with the legs' roles exchanged.

    The second step's phases and events are ``seq``'s with every contact renamed by
    ``pairing`` (contact -> the other leg's counterpart, e.g. ``tip_1 <-> tip_2``), their
    names suffixed :data:`SECOND_STEP`, and their points one step length further: a point
    ``pairing[c]`` stands at ``c``'s anchor + 1 (step lengths) with ``c``'s offset. Every
    share of the step time is halved (a share of the stride time ``2 L / v``), with its
    bounds. After the last event the stride repeats with ``x`` moved on by ``2 L``, the legs
    not swapped, so the two steps may differ (legs of unequal mass or shape); the step
    length ``L`` and the liftoff impulse ``P`` are shared by both steps."""
    if seq.steps != 1:
        raise ContactSequenceError(f"sequence {seq.name!r} is already a stride")

    def renamed(names: Sequence[str]) -> tuple[str, ...]:
        return tuple(swap_spec(c, pairing) for c in names)

    def half(ph: PhaseSpec, **changes: Any) -> PhaseSpec:
        bounds = None if ph.bounds is None else (ph.bounds[0] / 2.0, ph.bounds[1] / 2.0)
        return dataclasses.replace(ph, fraction=ph.fraction / 2.0, bounds=bounds, **changes)

    anchors = tuple((pairing.get(c, c), a + 1.0) for c, a in seq.anchors)
    offsets = tuple((pairing.get(c, c), b) for c, b in seq.offsets)
    second = tuple(half(ph, name=ph.name + SECOND_STEP, held=renamed(ph.held),
                        anchors=anchors, offsets=offsets) for ph in seq.phases)
    events = tuple(dataclasses.replace(ev, name=ev.name + SECOND_STEP,
                                       touchdown=renamed(ev.touchdown),
                                       release=renamed(ev.release)) for ev in seq.events)
    return dataclasses.replace(
        seq, name=f"{seq.name} stride", phases=tuple(half(ph) for ph in seq.phases) + second,
        events=seq.events + events, steps=2)
