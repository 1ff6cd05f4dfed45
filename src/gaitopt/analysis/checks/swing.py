"""The swing of each leg, read off a gait file: how often its foot reverses, how high it rises.

A leg's *swing* is the time none of its contact points is held (the contact points of a leg:
:func:`gaitopt.gait.model_defaults.legs_contacts`). A period (one step, or a stride) may cut
a swing in two: a leg released before the period ends lands after the next one starts. The
two runs are joined through the period map: after one step through the leg swap (the other
leg's run at the start of the step is what this leg does next), after a stride the leg's own
run at the start.

* ``distal joint``: the joint of the link that carries the leg's first contact point (the
  ankle of a foot, the knee of a point-foot shank).
* ``reversals``: how often the distal joint's angle turns back over the swing, counted with a
  hysteresis of :data:`REVERSAL_HYSTERESIS` (a turn counts once the angle has moved that far
  back from its last extreme; ripples smaller than that do not count). A person's ankle turns
  once or twice in swing (plantarflexed at toe-off, dorsiflexed to neutral by mid-swing, a
  little plantarflexion before the heel strikes); a foot flapping between its joint limits
  turns at every flap. ``swing.reversals`` fails above :data:`REVERSALS_LIMIT` (a required
  verify check: docs/feet.md, "Flapping feet").
* ``peak height``: the highest the foot's lowest contact point rises over the swing (m).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.checks.check import Check
from gaitopt.analysis.checks.samples import phase_of_samples
from gaitopt.gait.gait_file import Gait
from gaitopt.gait.model_defaults import legs_contacts

Array = NDArray[np.float64]

#: A turn of the distal joint's angle counts once it has gone back this far (rad; 2 deg).
REVERSAL_HYSTERESIS = float(np.radians(2.0))
#: The most turns of the distal joint in one swing that ``swing.reversals`` passes.
REVERSALS_LIMIT = 3


@dataclass(frozen=True)
class Swing:
    """One leg's swing over the gait's period, joined across the period's end.

    Attributes:
        leg: the leg's contact point names.
        joint: the distal joint's name.
        t: sample times (s), on one time line (the joined run shifted by the period).
        angle: the distal joint's angle at ``t`` (rad).
        height: the height of the foot's lowest contact point at ``t`` (m).
    """

    leg: tuple[str, ...]
    joint: str
    t: Array
    angle: Array
    height: Array

    @property
    def reversals(self) -> int:
        """Turns of :attr:`angle` (module docstring, :func:`count_reversals`)."""
        return count_reversals(self.angle, REVERSAL_HYSTERESIS)

    @property
    def peak_height(self) -> float:
        """The highest the foot rises (m)."""
        return float(np.max(self.height)) if self.height.size else 0.0


def count_reversals(x: Array, hysteresis: float) -> int:
    """How often the sequence ``x`` turns back by more than ``hysteresis`` from its last
    extreme (a zig-zag count: a monotone ``x`` has 0, one bump 1)."""
    values = np.asarray(x, dtype=float).reshape(-1)
    if values.size < 2:
        return 0
    turns, direction, hi, lo = 0, 0, values[0], values[0]
    for v in values[1:]:
        if direction == 0:
            hi, lo = max(hi, v), min(lo, v)
            if v > lo + hysteresis:
                direction, hi = 1, v
            elif v < hi - hysteresis:
                direction, lo = -1, v
        elif direction > 0:
            if v > hi:
                hi = v
            elif v < hi - hysteresis:
                turns, direction, lo = turns + 1, -1, v
        else:
            if v < lo:
                lo = v
            elif v > lo + hysteresis:
                turns, direction, hi = turns + 1, 1, v
    return turns


def _runs(mask: NDArray[np.bool_]) -> list[NDArray[np.int64]]:
    """Index arrays of the contiguous True runs of ``mask``."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    return [r for r in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if r.size]


def distal_joint(gait: Gait, leg: tuple[str, ...]) -> str:
    """The joint of the link carrying the leg's first contact point (module docstring)."""
    model = gait.model
    joint = model.links[model.link_index(model.contact(leg[0]).link)].joint
    if joint is None:  # a point on the base: no joint moves it
        raise ValueError(f"contact {leg[0]!r} is on the base link: no distal joint")
    return joint.name


def swings(gait: Gait) -> tuple[Swing, ...]:
    """Every leg's swing over the period (module docstring); a leg that never leaves the
    ground has none."""
    model, s = gait.model, gait.samples
    legs = [leg for leg in legs_contacts(model) if all(c in s.points for c in leg)]
    held = np.zeros((len(legs), s.t.size), dtype=bool)
    for ph, mask in zip(gait.phases, phase_of_samples(gait), strict=True):
        for i, leg in enumerate(legs):
            if any(c in ph.contacts for c in leg):
                held[i, mask] = True
    period, last = gait.period_steps * gait.step_time, s.t.size - 1
    out = []
    for i, leg in enumerate(legs):
        # The leg whose motion follows this one's across the period's end, and the one this
        # leg's motion follows from: the other leg after a step (the swap), itself after a
        # stride.
        nxt = 1 - i if gait.period_steps == 1 and len(legs) == 2 else i
        runs_next = _runs(~held[nxt])
        for r in _runs(~held[i]):
            starts, ends = r[0] == 0, r[-1] == last
            if starts and not ends and runs_next and runs_next[-1][-1] == last:
                continue  # the end of a swing that began in the previous period (below)
            group = [(i, r, 0.0)]
            if ends and not starts and runs_next and runs_next[0][0] == 0:
                group.append((nxt, runs_next[0][1:], period))  # its first sample repeats
            t, angle, height = [], [], []
            for j, run, shift in group:
                coordinate = model.joint_coordinate(distal_joint(gait, legs[j]))
                t.append(s.t[run] + shift)
                angle.append(s.q[run, coordinate])
                height.append(np.min(np.stack([s.points[c][run, 1] for c in legs[j]]), axis=0))
            out.append(Swing(leg=leg, joint=distal_joint(gait, leg), t=np.concatenate(t),
                             angle=np.concatenate(angle), height=np.concatenate(height)))
    return tuple(out)


def swing_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    """``swing.reversals``: the most turns of a distal joint in one swing (module
    docstring)."""
    worst, where = 0, "no swing"
    for sw in swings(gait):
        if sw.reversals >= worst:
            worst, where = sw.reversals, (f"{sw.joint} over the swing of "
                                          f"{'+'.join(sw.leg)} ({sw.t[0]:.3f}-{sw.t[-1]:.3f} s)")
    return [Check("swing.reversals", float(worst), lim["swing.reversals"], where)]
