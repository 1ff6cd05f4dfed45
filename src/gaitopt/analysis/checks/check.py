"""One verify check: a stable id, a measured value and its limit.

Every check has a stable identifier (``"eom.residual"``, ``"events.periodicity"``, ...) that
code, tests, ``gaitopt verify --json`` and the benchmarks use, and a prose name for people.
:data:`CHECKS` lists them in report order with their unit and default limit; ids never change
meaning (a check that changes meaning gets a new id), prose names may be reworded.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CheckSpec:
    """A check's stable ``id``, prose ``name``, ``unit`` and default ``limit`` (before
    ``tolerance_scale``); ``required=False``: reported for information, never fails."""

    id: str
    name: str
    unit: str
    limit: float
    required: bool = True


_SPECS = (
    # Knots: the full-coordinate fields (q, qd, qdd, u, contact_forces, contacts).
    CheckSpec("eom.residual", "equations of motion at the knots (residual / body weight x "
              "leg length)", "", 1e-6),
    CheckSpec("contacts.position", "held tips at their ground points (knots)", "m", 1e-6),
    CheckSpec("contacts.velocity", "held tips at rest (knots)", "m/s", 1e-6),
    CheckSpec("contacts.acceleration", "held tips not accelerating (knots)", "m/s^2", 1e-5),
    CheckSpec("contacts.normal_force", "normal contact force at the knots (negative part / "
              "body weight)", "", 1e-6),
    CheckSpec("contacts.friction", "friction cone (excess at knots and events)", "N|N s", 1e-3),
    CheckSpec("states.values", "phase states x equal to those of q, qd", "m|rad|m/s|rad/s", 1e-8),
    CheckSpec("states.rates", "phase state rates xdot equal to those of qd, qdd (full "
              "coordinates: up to the projection along the held points' normals)",
              "m/s|rad/s|m/s^2|rad/s^2", 1e-6),
    CheckSpec("parameters.consistency", "parameters agree with the phases and events "
              "(relative)", "", 1e-9),
    # Re-integration.
    CheckSpec("integration.interval", "re-integration per interval (error / the grid's error "
              "estimate)", "x estimate", 10.0),
    CheckSpec("integration.phase", "re-integration per phase (position drift)", "rad|m", 5e-2,
              required=False),
    # Events.
    CheckSpec("events.continuity", "events at phase boundaries: t, q continuous, qd_before / "
              "qd_after equal the phases' knots", "s|m|rad|m/s|rad/s", 1e-6),
    CheckSpec("events.maps", "impact and liftoff maps (velocities after the events)",
              "m/s|rad/s", 1e-6),
    CheckSpec("events.impulses", "impact and liftoff impulses", "N s", 1e-6),
    CheckSpec("events.periodicity", "periodicity of states (legs relabelled)", "m|rad|m/s|rad/s",
              1e-6),
    CheckSpec("events.periodic_controls", "periodicity of controls", "N m", 1e-3),
    # Dense samples and the constraints between knots.
    CheckSpec("samples.states", "samples q, qd on the phases' state interpolants",
              "m|rad|m/s|rad/s", 1e-8),
    CheckSpec("samples.controls", "samples u on the phases' control interpolants", "N m", 1e-9),
    CheckSpec("samples.points", "sample points at the kinematics of q", "m", 1e-9),
    CheckSpec("samples.normal_force", "normal contact force on dense samples (negative part)",
              "N", 1e-2),
    CheckSpec("bounds.torque", "torque bounds (excess)", "N m", 1e-6),
    CheckSpec("bounds.joints_knots", "joint limits at knots (excess)", "rad", 1e-6),
    CheckSpec("bounds.joints_samples", "joint limits between knots (excess)", "rad", 5e-2),
    CheckSpec("swing.clearance", "swing tip above ground (penetration)", "m", 5e-3),
    CheckSpec("swing.reversals", "turns of the swing leg's distal joint (ankle) in one swing "
              "(flapping)", "turns", 3.0),
    # The objective.
    CheckSpec("cost.recomputed", "cost recomputed from the file (relative)", "", 1e-6),
    # The solve's own accuracy.
    CheckSpec("accuracy.estimate", "grid error estimates of cost, speed and step length "
              "within the solve's accuracy target (largest, relative)", "", 1e-2),
)

#: Every check by id, in report order.
CHECKS: dict[str, CheckSpec] = {s.id: s for s in _SPECS}
#: Default limits by id (scaled by ``tolerance_scale``).
LIMITS: dict[str, float] = {s.id: s.limit for s in _SPECS}


@dataclass(frozen=True)
class Check:
    """One check's outcome: the measured ``value`` against ``limit`` (``value <= limit``
    passes); ``where`` says where the worst value was found (e.g. ``phases[0] knot 3``).
    ``unit`` defaults to the spec's."""

    id: str
    value: float
    limit: float
    where: str = ""
    unit_override: str | None = None

    def __post_init__(self) -> None:
        if self.id not in CHECKS:
            raise KeyError(f"unknown check id {self.id!r}")

    @property
    def name(self) -> str:
        """The prose name (for people; code uses :attr:`id`)."""
        return CHECKS[self.id].name

    @property
    def unit(self) -> str:
        return CHECKS[self.id].unit if self.unit_override is None else self.unit_override

    @property
    def required(self) -> bool:
        return CHECKS[self.id].required

    @property
    def passed(self) -> bool:
        """Within the limit; an informational check (``required=False``) always passes."""
        within = bool(np.isfinite(self.value) and self.value <= self.limit)
        return within or not self.required

    @property
    def limit_text(self) -> str:
        text = f"<= {self.limit:.3g} {self.unit}".rstrip()
        return text if self.required else f"({text}, information)"

    def to_dict(self) -> dict[str, object]:
        """Plain JSON data: ``id, name, value, limit, unit, required, passed, where``."""
        value = float(self.value)
        return {"id": self.id, "name": self.name,
                "value": value if np.isfinite(value) else None, "limit": float(self.limit),
                "unit": self.unit, "required": self.required, "passed": self.passed,
                "where": self.where}


@dataclass(frozen=True)
class Worst:
    """The largest value seen so far and where (a small accumulator for the checks)."""

    value: float = 0.0
    where: str = ""

    def update(self, value: float, where: str) -> Worst:
        v = float(value)
        if not np.isfinite(v):
            return self if not np.isfinite(self.value) else Worst(np.inf, where)
        return Worst(v, where) if v > self.value else self

    def check(self, id_: str, limits: dict[str, float]) -> Check:
        return Check(id_, self.value, limits[id_], self.where)
