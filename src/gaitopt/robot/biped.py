"""The biped boundary: a floating torso and two thigh-shank legs with tip contacts.

The walking problem and the Reduced Dynamics Algorithm need to know which links, joints,
contact points and actuators form each leg, which leg stands at the start of a step, how the
legs swap after it and where the base coordinates are in ``q``. :func:`biped_of` finds them
once per model in any model with that shape (not only the built-in ``five-link``) and explains
clearly what is missing otherwise; the walking code asks it for a :class:`Biped` instead of
looking at the model again.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import ClassVar

from gaitopt.robot.model import BASE_ANGLE, BASE_POSITION, RobotModel
from gaitopt.robot.symmetry import LegSwap, leg_swap


class BipedStructureError(ValueError):
    """The model is not a torso with two thigh-shank legs ending in contact points."""


@dataclass(frozen=True)
class Leg:
    """One two-link leg.

    Attributes:
        contact: name of the tip contact point.
        thigh, shank: link names.
        hip, knee: joint names; ``hip_index``, ``knee_index``: their indices in ``q``.
        thigh_length: hip-to-knee distance a1 (m); ``shank_length``: knee-to-tip distance a2 (m).
        hip_actuator, knee_actuator, ankle_actuator: actuator names (``None`` if absent).
    """

    contact: str
    thigh: str
    shank: str
    hip: str
    knee: str
    hip_index: int
    knee_index: int
    thigh_length: float
    shank_length: float
    hip_actuator: str | None
    knee_actuator: str | None
    ankle_actuator: str | None

    @property
    def length(self) -> float:
        """Length of the straight leg a1 + a2 (m)."""
        return self.thigh_length + self.shank_length

    def reach(self, knee: float) -> float:
        """Hip-to-tip distance (m) with the knee at angle ``knee`` (rad):
        ``sqrt(a1^2 + a2^2 + 2 a1 a2 cos(knee))``."""
        a1, a2 = self.thigh_length, self.shank_length
        return math.sqrt(a1 * a1 + a2 * a2 + 2.0 * a1 * a2 * math.cos(knee))


@dataclass(frozen=True)
class Biped:
    """The biped of a model: its two legs, which stands, how they swap, where the base is.

    Attributes:
        legs: ``legs[0]`` is leg 1 (the first contact point), the stance leg at the start of
            a step; ``legs[1]`` leg 2, the swing leg.
        swap: the leg swap after a step (the linear maps of ``q`` and ``u``, here
            permutations, and the contact names: :class:`~gaitopt.robot.symmetry.LegSwap`).
        reduced: the model is exactly a torso and these two legs (5 links, 7 coordinates),
            the shape the paper's reduced coordinates describe.
        base_position, base_angle: where the floating base's ``(x, y)`` (m, world frame) and
            angle (rad) are in ``q`` (the same for every model: :data:`BASE_POSITION`).
    """

    legs: tuple[Leg, Leg]
    swap: LegSwap
    reduced: bool
    base_position: ClassVar[slice] = BASE_POSITION
    base_angle: ClassVar[int] = BASE_ANGLE

    @property
    def stance(self) -> Leg:
        """Leg 1, standing at the origin at the start of a step."""
        return self.legs[0]

    @property
    def swing(self) -> Leg:
        """Leg 2, swinging at the start of a step and landing at ``(step_length, 0)``."""
        return self.legs[1]

    @property
    def contacts(self) -> tuple[str, str]:
        """The tip contact names ``(stance, swing)``."""
        return self.legs[0].contact, self.legs[1].contact

    def other(self, i: int) -> int:
        """The index of the other leg."""
        return 1 - i


@functools.lru_cache(maxsize=64)
def biped_of(model: RobotModel) -> Biped:
    """Identify the torso (the floating base) and the two legs of ``model``.

    Built once per model: the model is immutable, so equal models share one biped (the
    walking code asks for it in many places); a model that is no biped raises every time.

    Requirements, each reported by name when violated: exactly two contact points; each on a
    link (the shank) whose parent (the thigh) is attached to the base; the hip joints at the
    base origin; thighs and shanks pointing ``down``; the knee joint and the tip on the link
    axis (``across = 0``) at positive distances.
    """
    name = model.name
    if len(model.contacts) != 2:
        raise BipedStructureError(
            f"model {name!r}: a biped needs exactly two contact points (leg tips); "
            f"it has {len(model.contacts)}")
    legs = []
    for contact in model.contacts:
        shank = model.link(contact.link)
        if shank.parent is None or shank.joint is None:
            raise BipedStructureError(
                f"model {name!r}: contact {contact.name!r} is on the floating base; a leg tip "
                "must be on a shank (whose parent is a thigh attached to the base)")
        thigh = model.link(shank.parent)
        if thigh.parent != model.base.name or thigh.joint is None:
            raise BipedStructureError(
                f"model {name!r}: contact {contact.name!r} is on {shank.name!r}, whose parent "
                f"{thigh.name!r} is not attached to the base {model.base.name!r}; a leg is "
                "base -> thigh -> shank -> tip")
        for link in (thigh, shank):
            if link.direction != "down":
                raise BipedStructureError(
                    f"model {name!r}: leg link {link.name!r} has direction "
                    f"{link.direction!r}; leg links must point 'down'")
        if thigh.joint.at != (0.0, 0.0):
            raise BipedStructureError(
                f"model {name!r}: hip joint {thigh.joint.name!r} is at {thigh.joint.at} on the "
                "base; both hips must be at the base origin (0, 0)")
        knee_at, tip_at = shank.joint.at, contact.at
        if knee_at[1] != 0.0 or knee_at[0] <= 0.0:
            raise BipedStructureError(
                f"model {name!r}: knee joint {shank.joint.name!r} at {knee_at} must lie on "
                "the thigh axis at a positive distance (along > 0, across = 0)")
        if tip_at[1] != 0.0 or tip_at[0] <= 0.0:
            raise BipedStructureError(
                f"model {name!r}: contact {contact.name!r} at {tip_at} must lie on the shank "
                "axis at a positive distance (along > 0, across = 0)")

        def actuator(*, joint: str | None = None, contact_name: str | None = None) -> str | None:
            for a in model.actuators:
                if (joint is not None and a.joint == joint) or (
                        contact_name is not None and a.contact == contact_name):
                    return a.name
            return None

        legs.append(Leg(
            contact=contact.name, thigh=thigh.name, shank=shank.name,
            hip=thigh.joint.name, knee=shank.joint.name,
            hip_index=model.joint_coordinate(thigh.joint.name),
            knee_index=model.joint_coordinate(shank.joint.name),
            thigh_length=knee_at[0], shank_length=tip_at[0],
            hip_actuator=actuator(joint=thigh.joint.name),
            knee_actuator=actuator(joint=shank.joint.name),
            ankle_actuator=actuator(contact_name=contact.name),
        ))
    if legs[0].thigh == legs[1].thigh:
        raise BipedStructureError(f"model {name!r}: both contact points are on the same leg")
    return Biped(legs=(legs[0], legs[1]), swap=leg_swap(model), reduced=model.nq == 7)


def reduced_biped(model: RobotModel) -> Biped:
    """The biped of ``model`` (:func:`biped_of`), required to have no links beyond torso and
    legs: the shape of the paper's reduced coordinates (:mod:`gaitopt.dynamics.reduced`)."""
    biped = biped_of(model)
    if not biped.reduced:
        raise BipedStructureError(
            f"model {model.name!r} has {len(model.links)} links; the reduced biped dynamics "
            "need exactly a torso and two thigh-shank legs (5 links, 7 coordinates)")
    return biped


def has_reduced_shape(model: RobotModel) -> bool:
    """Whether ``model`` is a biped the reduced coordinates describe (:func:`reduced_biped`
    would not raise)."""
    try:
        reduced_biped(model)
    except BipedStructureError:
        return False
    return True
