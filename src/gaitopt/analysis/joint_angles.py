"""People's sagittal joint angles read off a gait file, over one stride of one leg.

Clinical gait analysis (Winter 2009, *Biomechanics and Motor Control of Human Movement*, 4th
ed., Wiley; Perry and Burnfield 2010, *Gait Analysis: Normal and Pathological Function*, 2nd
ed., SLACK) plots each joint's angle over one *stride* of one leg, from its heel strike (0 %)
to its next heel strike (100 %). A gait file holds one step; the stride is this step followed
by the same step with the legs swapped (:meth:`gaitopt.gait.record.file.Gait.stride_samples`,
legs labelled physically), or the file's own period for a stride file.

The leg is one of :func:`gaitopt.gait.options.model_defaults.legs_contacts` (leg 0: ``heel_1``,
``toe_1`` on the seven-link model). Its joints are those from the floating base down to the
link carrying its first contact point: hip, knee and ankle (the ankle is absent on a
point-foot leg). People's convention, in degrees, from the model's coordinates (radians;
docs/conventions.md: a joint angle is the child link's angle relative to its parent,
counter-clockwise positive, x forward):

* **hip flexion** ``= +q_hip``: the thigh's angle relative to the torso, 0 with the thigh
  along the torso's axis, positive with the thigh swung forward (flexion), negative behind it
  (extension);
* **knee flexion** ``= -q_knee``: the shank's angle relative to the thigh, 0 straight,
  positive flexed (the model's knee angle is negative when flexed);
* **ankle dorsiflexion** ``= +q_ankle``: the foot's angle relative to the shank, 0 with the
  sole at a right angle to the shank, positive with the toes up (dorsiflexion), negative
  toes down (plantarflexion).

*Stance* is the time any contact point of the leg is held (the file's phases' contacts; the
seven-link heel-toe walk: from the heel strike through foot flat and heel off to the toe-off),
*swing* the rest of the stride. The stride starts at the leg's *initial contact*: the start
of its stance (the heel strike on the heel-toe walk).

The four measures compared with people's (:func:`people_measures`), all in degrees:

* **stance knee flexion**: the largest knee flexion over the first half of stance (heel
  strike to mid-stance): people's loading-response peak, 15-20 deg, which this window
  separates from the knee's flexion before toe-off;
* **swing knee flexion**: the largest knee flexion over the swing (people: about 60 deg);
* **hip excursion**: max - min of the hip flexion over the stride (people: about 40 deg);
* **ankle excursion**: max - min of the ankle dorsiflexion over the stride (people: about
  30 deg).

The distance of a gait from people's (:func:`distance_from_people`) is the sum over the four
measures of the relative error ``|m - p| / p`` against the published value ``p`` (the middle
of a range: 17.5 deg for 15-20 deg).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from gaitopt.gait.options.model_defaults import legs_contacts
from gaitopt.gait.record.file import Gait
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import swap_names

Array = NDArray[np.float64]

#: The measures' names, in the order of the tables.
MEASURES: tuple[str, ...] = ("stance_knee_flexion", "swing_knee_flexion", "hip_excursion",
                             "ankle_excursion")
#: Published sagittal values of people walking at natural cadence, deg, as (low, high) (a
#: single "about" value as (v, v)): issue 28, consistent with Winter (2009) and Perry and
#: Burnfield (2010).
PEOPLE: dict[str, tuple[float, float]] = {
    "stance_knee_flexion": (15.0, 20.0),
    "swing_knee_flexion": (60.0, 60.0),
    "hip_excursion": (40.0, 40.0),
    "ankle_excursion": (30.0, 30.0),
}
#: What each measure is, in words (for tables and figures).
MEASURE_LABELS: dict[str, str] = {
    "stance_knee_flexion": "stance knee flexion (peak, first half of stance)",
    "swing_knee_flexion": "swing knee flexion (peak)",
    "hip_excursion": "hip excursion (max - min over the stride)",
    "ankle_excursion": "ankle excursion (max - min over the stride)",
}


@dataclass(frozen=True)
class JointAngleStride:
    """One leg's sagittal joint angles over one stride (module docstring), heel strike at 0.

    Attributes:
        leg: the leg's contact point names.
        joints: the leg's (hip, knee, ankle) joint names; ankle ``None`` on a point foot.
        percent: % of the stride at each sample, increasing, in [0, 100]; 0 and 100 are the
            same instant, the initial contact, with the angles interpolated linearly between
            the samples either side of it.
        hip: hip flexion, deg.
        knee: knee flexion, deg.
        ankle: ankle dorsiflexion, deg (NaN without an ankle).
        stance: whether the leg is in stance at each sample.
        stance_end: % of the stride at which stance ends (the toe-off).
        stride_time: the stride's duration, s (two step times).
    """

    leg: tuple[str, ...]
    joints: tuple[str, str, str | None]
    percent: Array
    hip: Array
    knee: Array
    ankle: Array
    stance: NDArray[np.bool_]
    stance_end: float
    stride_time: float


def leg_joints(model: RobotModel, leg: tuple[str, ...]) -> tuple[str, str, str | None]:
    """The joints from the base down to the link carrying ``leg[0]``: (hip, knee, ankle),
    ankle ``None`` for a chain of two joints (a point foot on the shank)."""
    chain: list[str] = []
    i = model.link_index(model.contact(leg[0]).link)
    while i >= 0:
        joint = model.links[i].joint
        if joint is not None:
            chain.append(joint.name)
        i = model.parent_index(i)
    chain.reverse()
    if len(chain) == 3:
        return chain[0], chain[1], chain[2]
    if len(chain) == 2:
        return chain[0], chain[1], None
    raise ValueError(f"leg {'+'.join(leg)}: expected a hip, a knee and perhaps an ankle from "
                     f"the base down, got the joints {chain}")


def stance_intervals(gait: Gait, leg: tuple[str, ...]) -> list[tuple[float, float]]:
    """The leg's stance intervals (s) over the stride of :meth:`Gait.stride_samples` (from the
    file's first sample time ``t0`` to ``t0`` plus two step times), merged where they touch.

    Step k of the stride is the file's step shifted by k step times; on an odd step of a
    one-step file the leg's points are the other leg's in the file (the swap)."""
    t0, step = float(gait.samples.t[0]), gait.step_time
    names = swap_names(gait.model) if gait.period_steps == 1 else {}
    raw: list[tuple[float, float]] = []
    for k in range(2 // gait.period_steps):
        physical = {names.get(c, c) if k % 2 else c for c in leg}  # the file's names
        for ph in gait.phases:
            if physical & set(ph.contacts):
                raw.append((float(ph.t[0]) + k * step, float(ph.t[-1]) + k * step))
    raw.sort()
    merged: list[tuple[float, float]] = []
    tol = 1e-9 * max(1.0, 2 * step)
    for a, b in raw:
        if merged and a <= merged[-1][1] + tol:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    # A stance running through the stride's end continues at its start: join the two.
    if len(merged) > 1 and merged[0][0] <= t0 + tol and merged[-1][1] >= t0 + 2 * step - tol:
        last = merged.pop()
        merged[0] = (last[0], merged[0][1] + 2 * step)
    return merged


def joint_angle_stride(gait: Gait, leg_index: int = 0) -> JointAngleStride:
    """Leg ``leg_index``'s joint angles over one stride from its initial contact (module
    docstring): the samples of :meth:`Gait.stride_samples` (two steps), their times mapped
    to % of the stride from the start of the leg's stance, modulo the stride."""
    model = gait.model
    leg = legs_contacts(model)[leg_index]
    joints = leg_joints(model, leg)
    intervals = stance_intervals(gait, leg)
    if not intervals:
        raise ValueError(f"leg {'+'.join(leg)} never touches the ground in this gait")
    if len(intervals) > 1:
        raise ValueError(f"leg {'+'.join(leg)} has {len(intervals)} stance phases in a "
                         f"stride; expected one")
    contact, toe_off = intervals[0]
    s = gait.stride_samples(2)
    stride = 2 * gait.step_time
    t0 = float(s.t[0])
    keep = s.t < t0 + stride - 1e-9 * max(1.0, stride)  # the last sample repeats the first
    t = s.t[keep]
    phase = np.mod(t - contact, stride)
    order = np.argsort(phase, kind="stable")
    phase = phase[order]
    q = s.q[keep][order]

    def coordinate(joint: str) -> Array:
        return np.asarray(np.degrees(q[:, model.joint_coordinate(joint)]), dtype=float)

    hip = coordinate(joints[0])
    knee = -coordinate(joints[1])
    ankle = coordinate(joints[2]) if joints[2] is not None else np.full(phase.size, np.nan)
    stance_end = (toe_off - contact) / stride
    # The initial contact falls between two samples: its angles interpolated linearly (the
    # angles are continuous; the impacts change only velocities), at 0 and again at 100 %.
    gap = phase[0] + (stride - phase[-1])
    w = phase[0] / gap if gap > 0 else 0.0

    def close(a: Array) -> Array:
        at_contact = (1.0 - w) * a[0] + w * a[-1]
        return np.concatenate([[at_contact], a, [at_contact]])

    percent = np.concatenate([[0.0], 100.0 * phase / stride, [100.0]])
    hip, knee, ankle = close(hip), close(knee), close(ankle)
    stance = percent <= 100.0 * stance_end + 1e-9
    stance[-1] = True
    return JointAngleStride(leg=leg, joints=joints, percent=percent, hip=hip, knee=knee,
                            ankle=ankle, stance=stance, stance_end=100.0 * stance_end,
                            stride_time=stride)


def people_measures(angles: JointAngleStride) -> dict[str, float]:
    """The four measures of the module docstring, deg, keyed by :data:`MEASURES`; besides,
    ``stance_percent`` (stance's share of the stride, %) and
    ``stance_knee_flexion_percent`` (where in the stride the stance knee flexion peak lies,
    %: at the window's end, half the stance share, it is no peak but a knee still bending)."""
    first_half = angles.stance & (angles.percent <= angles.stance_end / 2.0)
    swing = ~angles.stance
    knee = np.where(first_half, angles.knee, -np.inf)
    peak = int(np.argmax(knee))
    return {
        "stance_knee_flexion": float(knee[peak]),
        "swing_knee_flexion": float(np.max(angles.knee[swing])) if swing.any() else float("nan"),
        "hip_excursion": float(np.ptp(angles.hip)),
        "ankle_excursion": float(np.ptp(angles.ankle)),
        "stance_percent": angles.stance_end,
        "stance_knee_flexion_percent": float(angles.percent[peak]),
    }


def relative_errors(measures: dict[str, float]) -> dict[str, float]:
    """``|m - p| / p`` per measure of :data:`MEASURES`, ``p`` the middle of :data:`PEOPLE`'s
    range."""
    out = {}
    for name in MEASURES:
        low, high = PEOPLE[name]
        p = (low + high) / 2.0
        out[name] = abs(measures[name] - p) / p
    return out


def distance_from_people(measures: dict[str, float]) -> float:
    """The sum of :func:`relative_errors` over the four measures (0: people's values)."""
    return float(sum(relative_errors(measures).values()))
