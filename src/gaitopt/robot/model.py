"""The robot model: an immutable description of a planar kinematic tree.

A model is data only. Algorithms (``gaitopt.dynamics``) are free functions of it and never
modify it.

Frames and conventions (see ``docs/conventions.md``):

* World frame: x forward, y up, z out of the page; angles and torques CCW positive about z.
* Every link has a frame whose origin is its proximal joint (for the floating base: the base
  point, the hip of the five-link biped) and which is rotated by the link's absolute angle.
* A link extends from its origin along its *axis*, a unit vector fixed in its frame:
  ``(0, -1)`` for ``direction: down`` (legs: a link at absolute angle phi points along
  ``(sin phi, -cos phi)``), ``(0, 1)`` for ``direction: up`` (the torso).
* A point on a link is given as ``(along, across)``: ``along`` metres along the axis from the
  link origin, ``across`` metres along the axis turned 90 degrees CCW. Its coordinates in the
  link frame are ``along * axis + across * perp(axis)`` (see :meth:`Link.local_point`).
* Generalized coordinates: ``q = [x, y, angle_base, q_joint_1, ..., q_joint_n]`` where
  ``(x, y)`` is the world position of the base origin, ``angle_base`` the base's absolute angle
  and the joints follow in the order their links appear in the model. A revolute joint angle is
  the child's angle relative to its parent; 0 makes their frames parallel.
* Controls ``u``: one entry per actuator, in file order. A joint actuator applies +tau to the
  child link and -tau to the parent. A contact actuator (an ankle) applies +tau to the link
  carrying the contact point and -tau to the ground, only while that point is held.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field
from typing import Any, Literal

Direction = Literal["up", "down"]

AXIS_OF_DIRECTION: dict[str, tuple[float, float]] = {"up": (0.0, 1.0), "down": (0.0, -1.0)}

#: The model-file format and version that :func:`model_to_dict` writes (and
#: :mod:`gaitopt.robot.schema` reads).
FORMAT = "gaitopt.model"
VERSION = 1

#: Names of the three coordinates of the floating base, in order.
BASE_COORDINATES: tuple[str, str, str] = ("x", "y", "angle")
#: Indices in ``q`` of the base position (world frame, m) and the base angle (rad), in the
#: order of :data:`BASE_COORDINATES`; ``BASE_POSITION`` slices ``(x, y)`` out of ``q``.
BASE_X, BASE_Y, BASE_ANGLE = 0, 1, 2
BASE_POSITION = slice(BASE_X, BASE_Y + 1)


@dataclass(frozen=True)
class Joint:
    """A revolute joint between a link and its parent.

    ``at`` is the joint position on the parent as ``(along, across)`` in metres (see the module
    docstring); ``limits`` are the joint angle bounds in radians, ``lower <= upper``; ``-inf``
    (lower) or ``inf`` (upper) is no bound (a continuous joint has both; a model file writes
    them ``null``). ``damping`` ``b >= 0`` (N m s/rad) is a passive viscous torque ``-b qd``
    at the joint, which the dynamics include (:func:`gaitopt.dynamics.rnea.rnea`, the ABA, the
    contact dynamics); the actuators' torques, and so the costs, do not.
    """

    name: str
    at: tuple[float, float]
    limits: tuple[float, float]
    damping: float = 0.0


@dataclass(frozen=True)
class Shape:
    """A uniform solid that a link's inertia was computed from (kept for the record).

    ``type`` is ``"ellipsoid"`` (semi-axes ``length/2, radius, radius``: inertia about the axis
    normal to the plane ``m ((length/2)^2 + radius^2) / 5``) or ``"rod"`` (a thin rod:
    ``m length^2 / 12``, ``radius`` is ``None``). Lengths in m.
    """

    type: Literal["ellipsoid", "rod"]
    radius: float | None = None


@dataclass(frozen=True)
class Link:
    """A rigid link of the planar tree.

    Attributes:
        name: unique name.
        parent: name of the parent link; ``None`` for the floating base.
        joint: the revolute joint to the parent; ``None`` for the floating base.
        direction: ``"up"`` or ``"down"``: the link axis in its own frame.
        length: metres, > 0.
        mass: kilograms, >= 0.
        com: centre of mass as ``(along, across)`` in metres.
        inertia: rotational inertia about the centre of mass, about z, kg m^2, >= 0 (a point
            mass has 0; the model as a whole must have a positive definite mass matrix, which
            :mod:`gaitopt.robot.mass_matrix` checks when a model is loaded).
        shape: the shape the inertia was computed from (for the record), or ``None`` when the
            inertia was given directly.
    """

    name: str
    parent: str | None
    joint: Joint | None
    direction: Direction
    length: float
    mass: float
    com: tuple[float, float]
    inertia: float
    shape: Shape | None = None

    @property
    def axis(self) -> tuple[float, float]:
        """Unit vector of the link axis in the link frame."""
        return AXIS_OF_DIRECTION[self.direction]

    def local_point(self, along: float, across: float = 0.0) -> tuple[float, float]:
        """Coordinates in the link frame (m) of the point ``(along, across)``."""
        ax, ay = self.axis
        return (along * ax - across * ay, along * ay + across * ax)

    @property
    def com_local(self) -> tuple[float, float]:
        """Centre of mass in the link frame (m)."""
        return self.local_point(*self.com)


@dataclass(frozen=True)
class Contact:
    """A point on a link that can touch the ground (a leg tip), as ``(along, across)`` in m."""

    name: str
    link: str
    at: tuple[float, float]


@dataclass(frozen=True)
class Actuator:
    """A torque source with bounds ``limits = (lower, upper)`` in N m.

    Exactly one of ``joint`` (a joint torque) and ``contact`` (a torque between the ground and
    the link carrying the contact point, e.g. an ankle) is set.
    """

    name: str
    limits: tuple[float, float]
    joint: str | None = None
    contact: str | None = None

    @property
    def kind(self) -> Literal["joint", "contact"]:
        return "joint" if self.joint is not None else "contact"


@dataclass(frozen=True)
class SymmetrySpec:
    """A declared left/right symmetry: pairs of link names and of contact names that swap
    with a step (see :mod:`gaitopt.robot.symmetry`)."""

    links: tuple[tuple[str, str], ...]
    contacts: tuple[tuple[str, str], ...]


@dataclass(frozen=True)
class RobotModel:
    """An immutable planar multibody model (a tree with a floating base).

    ``links[0]`` is the floating base; every other link comes after its parent. ``gravity`` is
    the world gravity vector in m/s^2. ``symmetry`` is the declared left/right symmetry, or
    None (then it is inferred where needed: :func:`gaitopt.robot.symmetry.model_symmetry`).
    """

    name: str
    links: tuple[Link, ...]
    contacts: tuple[Contact, ...]
    actuators: tuple[Actuator, ...]
    gravity: tuple[float, float] = (0.0, -9.81)
    description: str = ""
    symmetry: SymmetrySpec | None = None
    _index: dict[str, int] = field(default_factory=dict, init=False, repr=False, compare=False)
    # ``_index`` is derived from ``links`` and excluded from ``==`` and ``hash``; models are
    # hashable (usable as cache keys) because every field is immutable.

    def __post_init__(self) -> None:
        object.__setattr__(self, "_index", {link.name: i for i, link in enumerate(self.links)})

    # -- sizes -------------------------------------------------------------------------------
    @property
    def base(self) -> Link:
        return self.links[0]

    @property
    def nq(self) -> int:
        """Number of generalized coordinates (= velocities), 3 for the base + one per joint."""
        return 3 + len(self.links) - 1

    @property
    def nu(self) -> int:
        """Number of actuators (controls)."""
        return len(self.actuators)

    @property
    def total_mass(self) -> float:
        """Sum of the link masses (kg)."""
        return sum(link.mass for link in self.links)

    # -- names and indices -------------------------------------------------------------------
    @property
    def joints(self) -> tuple[Joint, ...]:
        return tuple(link.joint for link in self.links[1:] if link.joint is not None)

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        """Names of the entries of ``q`` (``x, y, <base>``, then the joints)."""
        return ("x", "y", self.base.name) + tuple(j.name for j in self.joints)

    def link_index(self, name: str) -> int:
        try:
            return self._index[name]
        except KeyError:
            raise KeyError(f"model {self.name!r} has no link {name!r}") from None

    def link(self, name: str) -> Link:
        return self.links[self.link_index(name)]

    def parent_index(self, i: int) -> int:
        """Index of the parent of link ``i`` (-1 for the base)."""
        parent = self.links[i].parent
        return -1 if parent is None else self.link_index(parent)

    @property
    def coordinate_damping(self) -> tuple[float, ...]:
        """``(nq,)``: each coordinate's joint damping ``b`` (N m s/rad; 0 on the base
        coordinates), :attr:`Joint.damping`."""
        return (0.0, 0.0, 0.0) + tuple(link.joint.damping if link.joint is not None else 0.0
                                       for link in self.links[1:])

    def coordinate_of_link(self, i: int) -> int:
        """Index in ``q`` of the joint coordinate of link ``i >= 1`` (the base uses 0, 1, 2)."""
        return 2 if i == 0 else 2 + i

    def joint_coordinate(self, joint: str) -> int:
        """Index in ``q`` of a joint's angle."""
        for i, link in enumerate(self.links[1:], start=1):
            if link.joint is not None and link.joint.name == joint:
                return self.coordinate_of_link(i)
        raise KeyError(f"model {self.name!r} has no joint {joint!r}")

    def contact(self, name: str) -> Contact:
        for c in self.contacts:
            if c.name == name:
                return c
        raise KeyError(f"model {self.name!r} has no contact point {name!r}")

    def actuator_index(self, name: str) -> int:
        for i, a in enumerate(self.actuators):
            if a.name == name:
                return i
        raise KeyError(f"model {self.name!r} has no actuator {name!r}")

    def chain(self, i: int) -> tuple[int, ...]:
        """Link indices from the base to link ``i`` inclusive."""
        out = [i]
        while (p := self.parent_index(out[-1])) >= 0:
            out.append(p)
        return tuple(reversed(out))

    # -- identity ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The model as plain data in the model-file schema (:func:`model_to_dict`; read back
        by :func:`gaitopt.robot.schema.model_from_dict`)."""
        return model_to_dict(self)

    def content_hash(self) -> str:
        """A short hash of the whole model description (every field of ``to_dict()``), e.g. as
        a cache key: equal models have equal hashes."""
        text = json.dumps(self.to_dict(), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


# -- model -> plain data ---------------------------------------------------------------------

def model_to_dict(model: RobotModel) -> dict[str, Any]:
    """The model as plain data in the model-file schema (:data:`FORMAT`, :data:`VERSION`).

    Every default is written out; a link keeps its ``shape`` (if any) next to the explicit
    ``inertia``. ``gaitopt.robot.schema.model_from_dict(model_to_dict(m)) == m``.
    """
    links: list[dict[str, Any]] = []
    for link in model.links:
        entry: dict[str, Any] = {"name": link.name, "parent": link.parent}
        if link.joint is not None:
            entry["joint"] = {"name": link.joint.name, "at": list(link.joint.at),
                              "limits": [x if math.isfinite(x) else None
                                         for x in link.joint.limits]}
            if link.joint.damping:  # written only where set: older models keep their hash
                entry["joint"]["damping"] = link.joint.damping
        entry.update({"direction": link.direction, "length": link.length, "mass": link.mass,
                      "com": list(link.com), "inertia": link.inertia})
        if link.shape is not None:
            entry["shape"] = ({"type": "ellipsoid", "radius": link.shape.radius}
                              if link.shape.type == "ellipsoid" else {"type": "rod"})
        links.append(entry)
    actuators: list[dict[str, Any]] = []
    for a in model.actuators:
        target = {"joint": a.joint} if a.joint is not None else {"contact": a.contact}
        actuators.append({"name": a.name, **target, "limits": list(a.limits)})
    out = {
        "format": FORMAT, "version": VERSION, "name": model.name,
        "description": model.description, "gravity": list(model.gravity), "links": links,
        "contacts": [{"name": c.name, "link": c.link, "at": list(c.at)} for c in model.contacts],
        "actuators": actuators,
    }
    if model.symmetry is not None:  # only when declared: older models keep their hash
        out["symmetry"] = {"links": [list(p) for p in model.symmetry.links],
                           "contacts": [list(p) for p in model.symmetry.contacts]}
    return out
