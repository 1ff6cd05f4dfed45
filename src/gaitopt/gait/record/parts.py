"""The parts of a gait record: a phase at its knots, a contact event and the dense samples.

Each is a frozen dataclass whose constructor checks every field (shapes, finiteness, times
increasing) and raises :class:`~gaitopt.gait.record.fields.GaitFileError` naming it; the
:class:`~gaitopt.gait.record.file.Gait` that holds them checks their consistency with the model
(:mod:`gaitopt.gait.record.checks`). Units and frames as in :mod:`gaitopt.gait.record.file`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from gaitopt.gait.record.fields import (
    Array,
    array_of,
    bad_field,
    check_increasing,
    mapping_of,
    number_of,
)

#: World points every gait's samples carry (leg numbers as in the step: leg 1 stands).
POINT_NAMES: tuple[str, ...] = ("hip", "torso_top")
#: Events of the built-in contact sequences: a walk's heel strike (touchdown) and liftoff
#: (release, with the liftoff impulse); a run's toe-off (release) and touchdown.
EVENT_NAMES: tuple[str, ...] = ("heel_strike", "liftoff", "toe_off", "touchdown")
#: Interpolation rules gaitopt can evaluate (:mod:`gaitopt.gait.record.interpolation`).
STATE_INTERPOLATIONS: tuple[str, ...] = ("cubic_hermite",)
CONTROL_INTERPOLATIONS: tuple[str, ...] = ("piecewise_linear",)
DEFAULT_INTERPOLATION: Mapping[str, str] = MappingProxyType({
    "states": "cubic_hermite",
    "controls": "piecewise_linear",
    "description": "reduced states x: cubic Hermite between knots using xdot; controls u: "
                   "piecewise linear between knots; q and qd are functions of x",
})


@dataclass(frozen=True, kw_only=True, eq=False)
class GaitPhase:
    """One phase at its K knots: time (s), coordinates, controls, contact forces, states.

    ``contacts`` are the contact names on the ground; ``contact_forces`` maps each of them to
    the (K, 2) world-frame force of the ground on the tip (N). ``x``/``xdot`` (K, n) are the
    phase's reduced (independent) states and their time derivatives, named by
    ``state_names``; ``interpolation`` says how the transcription interpolates between knots.
    """

    name: str
    contacts: tuple[str, ...]
    t: Array
    q: Array
    qd: Array
    qdd: Array
    u: Array
    contact_forces: Mapping[str, Array]
    state_names: tuple[str, ...]
    x: Array
    xdot: Array
    interpolation: Mapping[str, str] = field(default_factory=lambda: dict(DEFAULT_INTERPOLATION))
    #: Optional (K-1,) per-interval error estimate of the transcription (relative, >= 0; see
    #: :mod:`gaitopt.ocp.estimate`); ``None`` in files written before it existed.
    error_estimate: Array | None = None
    #: Optional (K, n) costates at the knots by ``state_names`` (cost per unit of each state,
    #: sign convention H = L + lambda^T f; :func:`gaitopt.ocp.costates`); ``None`` in files
    #: written before it existed or when the transcription gives none.
    costates: Array | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise bad_field("name", "expected a non-empty string")
        set_ = object.__setattr__
        set_(self, "contacts", tuple(self.contacts))
        set_(self, "state_names", tuple(self.state_names))
        t = array_of("t", self.t, (None,))
        if t.size < 2:
            raise bad_field("t", f"a phase needs at least 2 knots, got {t.size}")
        check_increasing("t", t)
        k, n = t.size, len(self.state_names)
        set_(self, "t", t)
        q = array_of("q", self.q, (k, None))
        set_(self, "q", q)
        for name in ("qd", "qdd"):
            set_(self, name, array_of(name, getattr(self, name), (k, q.shape[1])))
        set_(self, "u", array_of("u", self.u, (k, None)))
        set_(self, "x", array_of("x", self.x, (k, n)))
        set_(self, "xdot", array_of("xdot", self.xdot, (k, n)))
        forces = mapping_of("contact_forces", self.contact_forces)
        if set(forces) != set(self.contacts):
            raise bad_field("contact_forces", f"keys {sorted(forces)} must be the contacts on the "
                            f"ground {sorted(self.contacts)}")
        set_(self, "contact_forces", MappingProxyType(
            {c: array_of(f"contact_forces.{c}", forces[c], (k, 2)) for c in self.contacts}))
        interp = mapping_of("interpolation", self.interpolation, required=("states", "controls"))
        set_(self, "interpolation", MappingProxyType({str(a): str(b) for a, b in interp.items()}))
        if self.error_estimate is not None:
            est = array_of("error_estimate", self.error_estimate, (k - 1,))
            if np.any(est < 0.0):
                raise bad_field("error_estimate", "expected numbers >= 0")
            set_(self, "error_estimate", est)
        if self.costates is not None:
            set_(self, "costates", array_of("costates", self.costates, (k, n)))

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])


@dataclass(frozen=True, kw_only=True, eq=False)
class GaitEvent:
    """A contact event: ``heel_strike`` (inelastic impact) or ``liftoff`` (with its impulse).

    ``leg`` is the contact that strikes or lifts off; ``impulses`` maps each contact receiving
    an impulse to its (2,) world-frame impulse of the ground on the tip (N s); ``qd_before``
    and ``qd_after`` are the (nq,) velocities just before and after the event.
    """

    name: str
    t: float
    leg: str
    impulses: Mapping[str, Array]
    qd_before: Array
    qd_after: Array

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise bad_field("name", f"expected an event name (letters, digits, '_'; the built-in "
                            f"sequences use {', '.join(EVENT_NAMES)}), got {self.name!r}")
        set_ = object.__setattr__
        set_(self, "t", number_of("t", self.t))
        imp = mapping_of("impulses", self.impulses)
        set_(self, "impulses", MappingProxyType(
            {str(c): array_of(f"impulses.{c}", v, (2,)) for c, v in imp.items()}))
        before = array_of("qd_before", self.qd_before, (None,))
        set_(self, "qd_before", before)
        set_(self, "qd_after", array_of("qd_after", self.qd_after, before.shape))


@dataclass(frozen=True, kw_only=True, eq=False)
class GaitSamples:
    """Dense samples: ``t`` (N,) s, ``q``/``qd`` (N, nq), ``u`` (N, nu), ``points`` name ->
    (N, 2) world positions (m) of at least :data:`POINT_NAMES` (the recorded points are
    those of :func:`gaitopt.gait.solve.record.sample_points`: for the five-link biped also
    ``knee_1, knee_2, tip_1, tip_2``)."""

    t: Array
    q: Array
    qd: Array
    u: Array
    points: Mapping[str, Array]

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        t = array_of("t", self.t, (None,))
        if t.size < 2:
            raise bad_field("t", f"need at least 2 samples, got {t.size}")
        check_increasing("t", t)
        n = t.size
        set_(self, "t", t)
        q = array_of("q", self.q, (n, None))
        set_(self, "q", q)
        set_(self, "qd", array_of("qd", self.qd, (n, q.shape[1])))
        set_(self, "u", array_of("u", self.u, (n, None)))
        points = mapping_of("points", self.points, required=POINT_NAMES)
        set_(self, "points", MappingProxyType(
            {str(p): array_of(f"points.{p}", v, (n, 2)) for p, v in points.items()}))
