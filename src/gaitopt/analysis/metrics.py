"""Figures of merit of a gait, read off its record: what a user checks first.

All quantities come from the gait file alone (knots, events and dense samples), so they are
the same whether the gait was just solved or loaded from disk.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.checks.samples import phase_of_samples
from gaitopt.gait.cost import impulse_events
from gaitopt.gait.gait_file import Gait

#: Normal forces/impulses below this (N, N s) are treated as zero in friction ratios.
NORMAL_FLOOR = 1e-6


@dataclass(frozen=True)
class GaitMetrics:
    """Summary numbers of one gait.

    Attributes:
        peak_torques: by actuator, the largest |u| over the knots and samples (N m).
        torque_bounds: by actuator, the larger |bound| (N m).
        min_normal_force: smallest normal contact force over all knots of all phases (N).
        min_normal_impulse: smallest normal impulse over the events' contacts (N s).
        swing_clearance: largest height of the swing tip during single support (m).
        swing_min_height: smallest height of the swing tip over the dense samples of single
            support (m); negative values are penetration between collocation points.
        friction_required: largest |tangential| / normal over forces and impulses.
        friction_where: where that ratio is largest: ``"<contact>, knot k of <phase>"`` or
            ``"<contact>, <event> impulse"`` ("" without contacts).
        friction_tangential, friction_normal: the tangential and normal force (N) or impulse
            (N s) there; a normal part near 0 with a tangential part that is not (a tip
            unloading while the frictionless ground still pushes it sideways) makes the ratio
            unbounded.
    """

    peak_torques: dict[str, float]
    torque_bounds: dict[str, float]
    min_normal_force: float
    min_normal_impulse: float
    swing_clearance: float
    swing_min_height: float
    friction_required: float
    friction_where: str = ""
    friction_tangential: float = 0.0
    friction_normal: float = 0.0


def swing_heights(gait: Gait) -> NDArray[np.float64]:
    """Heights (m) of the swing foot at the samples where a leg has no point on the ground:
    the lowest of that leg's contact points (names ending ``_1`` / ``_2``; the swing tip of a
    point-foot walk in single support)."""

    s = gait.samples
    contacts = [c.name for c in gait.model.contacts]
    out = []
    for ph, mask in zip(gait.phases, phase_of_samples(gait), strict=True):
        for leg in ("_1", "_2"):
            points = [c for c in contacts if c.endswith(leg) and c in s.points]
            if points and not any(c in ph.contacts for c in points) and mask.any():
                out.append(np.min(np.stack([s.points[c][mask, 1] for c in points]), axis=0))
    return np.concatenate(out) if out else np.zeros(1)


def gait_metrics(gait: Gait) -> GaitMetrics:
    """The :class:`GaitMetrics` of ``gait``."""
    model = gait.model
    u_all = np.vstack([ph.u for ph in gait.phases] + [gait.samples.u])
    peaks = {a.name: float(np.max(np.abs(u_all[:, i]))) for i, a in enumerate(model.actuators)}
    bounds = {a.name: float(max(abs(a.limits[0]), abs(a.limits[1]))) for a in model.actuators}
    forces = [f for ph in gait.phases for f in ph.contact_forces.values()]
    min_force = float(min(np.min(f[:, 1]) for f in forces))
    lifting = impulse_events(gait)  # their lifting tips' pushes are not contact impulses
    impulses = [(e, c, i) for e in gait.events for c, i in e.impulses.items()
                if not (e in lifting and c == e.leg)]
    min_impulse = float(min((i[1] for _, _, i in impulses), default=0.0))
    # Every (tangential, normal) pair with where it acts: knots of the phases, then events.
    pairs: list[tuple[str, NDArray[np.float64]]] = [
        (f"{c}, knot {{k}} of {ph.name}", f)
        for ph in gait.phases for c, f in ph.contact_forces.items()]
    pairs += [(f"{c}, {e.name} impulse", np.asarray(i, dtype=float).reshape(1, 2))
              for e, c, i in impulses
              if abs(i[0]) > NORMAL_FLOOR or i[1] > NORMAL_FLOOR]
    friction, where, tangential, normal = 0.0, "", 0.0, 0.0
    for label, f in pairs:
        ratio = np.abs(f[:, 0]) / np.maximum(f[:, 1], NORMAL_FLOOR)
        k = int(np.argmax(ratio))
        if ratio[k] > friction:
            friction, where = float(ratio[k]), label.format(k=k)
            tangential, normal = float(f[k, 0]), float(f[k, 1])
    swing = swing_heights(gait)
    return GaitMetrics(peak_torques=peaks, torque_bounds=bounds, min_normal_force=min_force,
                       min_normal_impulse=min_impulse,
                       swing_clearance=float(np.max(swing)),
                       swing_min_height=float(np.min(swing)), friction_required=friction,
                       friction_where=where, friction_tangential=tangential,
                       friction_normal=normal)
