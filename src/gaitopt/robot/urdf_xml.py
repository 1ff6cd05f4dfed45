"""Reading URDF XML into plain records: links (mass, centre of mass, inertia tensor), joints
(type, parent, child, origin, axis, limits, effort) and the ``<gaitopt>`` element.

Units as in URDF: m, kg, kg m^2, rad, N m. Every problem is a one-line
:class:`~gaitopt.robot.errors.ModelError` naming the link or joint and what is allowed. The
frames and what the records become are in :mod:`gaitopt.robot.urdf` and ``docs/urdf.md``.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gaitopt.robot.errors import ModelError

#: Name prefix of the fixed joints that mark contact frames (``gaitopt_contact_tip_1``).
CONTACT_PREFIX = "gaitopt_contact_"
#: Limits (rad) of a continuous joint: none.
CONTINUOUS_LIMITS = (-math.inf, math.inf)
#: The collision geometries read (``<mesh>`` is read as a name only: no contact from it).
GEOMETRIES = ("sphere", "box", "cylinder", "capsule", "mesh")
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


@dataclass
class ULink:
    """A URDF link: ``mass`` (kg, 0 without ``<inertial>``), ``com`` (m, link frame) and the
    inertia tensor about the centre of mass along the link frame's axes (kg m^2, (3, 3))."""

    name: str
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))      # link frame, m
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # link axes, at com
    collisions: list[UCollision] = field(default_factory=list)


@dataclass
class UCollision:
    """A ``<collision>`` of a link: ``kind`` (one of :data:`GEOMETRIES`), its frame in the
    link frame (``rot`` (3, 3), ``pos`` (3,), m) and its sizes (m): ``radius`` (sphere,
    cylinder, capsule), ``length`` (cylinder, capsule: along the frame's z), ``size`` (box:
    x, y, z)."""

    kind: str
    rot: np.ndarray
    pos: np.ndarray
    radius: float = 0.0
    length: float = 0.0
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass
class UJoint:
    """A URDF joint; ``limits`` (rad) only for revolute (as written; ``inf``: no bound) and
    continuous (:data:`CONTINUOUS_LIMITS`) joints, ``effort`` (N m) ``None`` without
    ``<limit>``."""

    name: str
    type: str
    parent: str
    child: str
    rot: np.ndarray       # child frame axes in the parent frame (3, 3)
    pos: np.ndarray       # child origin in the parent frame (3,), m
    axis: np.ndarray      # unit vector in the child frame
    limits: tuple[float, float] | None
    effort: float | None
    damping: float = 0.0  # <dynamics damping>, N m s/rad


def rpy_matrix(r: float, p: float, y: float) -> np.ndarray:
    """URDF's fixed-axis roll-pitch-yaw: ``Rz(y) Ry(p) Rx(r)``."""
    if r == p == y == 0.0:
        return np.eye(3)
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                              math.cos(y), math.sin(y))
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rz @ ry @ rx


class Reader:
    """Parses the XML of one URDF; ``source`` names it in errors."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, value: Any, allowed: str, problem: str | None = None) -> ModelError:
        return ModelError(self.source, where, value, allowed, problem=problem)

    def number(self, where: str, text: str | None, default: float | None = None, *,
               infinite: bool = False) -> float:
        """A finite number, or with ``infinite`` also ``inf``, ``Inf``, ``+inf``, ``-inf``
        (any case, as Drake writes unbounded limits)."""
        allowed = "a number (inf or -inf: no bound)" if infinite else "a finite number"
        if text is None:
            if default is None:
                raise self.fail(where, None, allowed, problem="missing")
            return default
        try:
            x = float(text)
        except ValueError:
            x = math.nan
        if math.isnan(x) or (math.isinf(x) and not infinite):
            raise self.fail(where, text, allowed)
        return x

    def size(self, where: str, text: str | None) -> float:
        """A length >= 0 (m)."""
        x = self.number(where, text)
        if x < 0.0:
            raise self.fail(where, text, "a size >= 0 (m)")
        return x

    def vector(self, where: str, text: str | None, default: tuple[float, ...]) -> np.ndarray:
        if text is None:
            return np.array(default, dtype=float)
        parts = text.split()
        if len(parts) != 3:
            raise self.fail(where, text, "three numbers separated by spaces")
        return np.array([self.number(where, t) for t in parts])

    def origin(self, where: str, elem: ET.Element | None) -> tuple[np.ndarray, np.ndarray]:
        if elem is None:
            return np.eye(3), np.zeros(3)
        rpy = self.vector(f"{where} origin rpy", elem.get("rpy"), (0.0, 0.0, 0.0))
        xyz = self.vector(f"{where} origin xyz", elem.get("xyz"), (0.0, 0.0, 0.0))
        return rpy_matrix(*rpy), xyz

    def name(self, where: str, elem: ET.Element, attr: str = "name") -> str:
        value = elem.get(attr)
        if not value:
            raise self.fail(where, value, f"a non-empty '{attr}' attribute", problem="missing")
        return value

    def link(self, elem: ET.Element) -> ULink:
        link = ULink(self.name("<link>", elem))
        where = f"link {link.name!r}"
        link.collisions = [self.collision(where, c) for c in elem.findall("collision")]
        inertial = elem.find("inertial")
        if inertial is None:
            return link
        mass = inertial.find("mass")
        if mass is None:
            raise self.fail(f"{where} <inertial>", None, "a <mass value=...> in <inertial>",
                            problem="no <mass>")
        link.mass = self.number(f"{where} mass", mass.get("value"))
        if link.mass < 0.0:
            raise self.fail(f"{where} mass", link.mass, "a mass >= 0 (kg)")
        tensor = inertial.find("inertia")
        if tensor is None:
            if link.mass > 0.0:
                raise self.fail(f"{where} <inertial>", link.mass,
                                "an <inertia ixx iyy izz .../> with every mass",
                                problem=f"mass {link.mass:g} kg but no <inertia>")
            return link
        i = {k: self.number(f"{where} inertia {k}", tensor.get(k), None if k in (
            "ixx", "iyy", "izz") else 0.0) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        local = np.array([[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]],
                          [i["ixz"], i["iyz"], i["izz"]]])
        rot, link.com = self.origin(where + " inertial", inertial.find("origin"))
        link.inertia = rot @ local @ rot.T  # about the com, along the link frame's axes
        return link

    def collision(self, where: str, elem: ET.Element) -> UCollision:
        rot, pos = self.origin(f"{where} collision", elem.find("origin"))
        geometry = elem.find("geometry")
        shapes = [] if geometry is None else [
            g for g in geometry if isinstance(g.tag, str)
            and g.tag.rpartition("}")[2].rpartition(":")[2] in GEOMETRIES]
        if not shapes:
            raise self.fail(f"{where} collision", None, "a <geometry> with a sphere, box, "
                            "cylinder, capsule or mesh", problem="no geometry")
        g = shapes[0]
        kind = g.tag.rpartition("}")[2].rpartition(":")[2]
        at = f"{where} collision {kind}"
        out = UCollision(kind, rot, pos)
        if kind in ("sphere", "cylinder", "capsule"):
            out.radius = self.size(f"{at} radius", g.get("radius"))
        if kind in ("cylinder", "capsule"):
            out.length = self.size(f"{at} length", g.get("length"))
        if kind == "box":
            size = self.vector(f"{at} size", g.get("size") or "", (0.0, 0.0, 0.0))
            if np.any(size < 0.0):
                raise self.fail(f"{at} size", g.get("size"), "three sizes >= 0 (m)")
            out.size = (float(size[0]), float(size[1]), float(size[2]))
        return out

    def joint(self, elem: ET.Element) -> UJoint:
        name = self.name("<joint>", elem)
        where = f"joint {name!r}"
        kind = elem.get("type")
        if kind not in JOINT_TYPES:
            raise self.fail(f"{where} type", kind, f"one of {', '.join(JOINT_TYPES)}")
        if elem.find("mimic") is not None:
            raise self.fail(where, "mimic", "joints with their own coordinate (no <mimic>)",
                            problem="a mimic joint")
        ends = []
        for tag in ("parent", "child"):
            e = elem.find(tag)
            if e is None:
                raise self.fail(f"{where} <{tag}>", None, f"a <{tag} link=...>",
                                problem="missing")
            ends.append(self.name(f"{where} <{tag}>", e, "link"))
        rot, pos = self.origin(where, elem.find("origin"))
        axis_elem = elem.find("axis")
        axis = self.vector(f"{where} axis", None if axis_elem is None else axis_elem.get("xyz"),
                           (1.0, 0.0, 0.0))
        norm = float(np.linalg.norm(axis))
        if norm == 0.0:
            raise self.fail(f"{where} axis", "0 0 0", "a non-zero axis vector")
        limit = elem.find("limit")
        limits, effort = None, None
        if limit is not None:
            effort = self.number(f"{where} limit effort", limit.get("effort"), 0.0)
            if effort < 0.0:
                raise self.fail(f"{where} limit effort", effort, "an effort >= 0 (N m)")
            if kind == "revolute":
                lo = self.number(f"{where} limit lower", limit.get("lower"), 0.0, infinite=True)
                hi = self.number(f"{where} limit upper", limit.get("upper"), 0.0, infinite=True)
                if lo == math.inf or hi == -math.inf:
                    raise self.fail(f"{where} limit", f"lower {lo:g}, upper {hi:g}",
                                    "lower < inf and upper > -inf (rad)")
                if lo > hi:
                    raise self.fail(f"{where} limit", f"{lo:g} > {hi:g}", "lower <= upper (rad)")
                limits = (lo, hi)
        if kind == "revolute" and limits is None:
            raise self.fail(f"{where} <limit>", None, "a <limit lower upper effort velocity> "
                            "on a revolute joint (or type continuous)", problem="missing")
        if kind == "continuous":
            limits = CONTINUOUS_LIMITS
        damping = 0.0
        dyn = elem.find("dynamics")
        if dyn is not None:
            damping = self.number(f"{where} dynamics damping", dyn.get("damping"), 0.0)
            if damping < 0.0:
                raise self.fail(f"{where} dynamics damping", damping,
                                "a damping >= 0 (N m s/rad)")
        return UJoint(name, kind, ends[0], ends[1], rot, pos, axis / norm, limits, effort,
                      damping)



def transmission_joints(r: Reader, root: ET.Element) -> list[tuple[str, str]]:
    """``(joint, actuator)`` names of the ``<transmission>`` elements, in file order, in
    either ROS format: ``<transmission><joint name=J>...</joint><actuator name=A>...``
    (ros_control) or ``<transmission type="SimpleTransmission"><joint name=J/><actuator
    name=A/>`` (the old one, Drake's); the actuator name is the joint's if none is given."""
    out = []
    for t in root.findall("transmission"):
        where = f"transmission {t.get('name') or '(unnamed)'!r}"
        joints = t.findall("joint")
        if not joints:
            raise r.fail(where, None, "a <joint name=...> in every <transmission>",
                         problem="no <joint>")
        actuator = t.find("actuator")
        for j in joints:
            name = r.name(f"{where} <joint>", j)
            out.append((name, name if actuator is None else actuator.get("name") or name))
    return out


class Extension:
    """The ``<gaitopt>`` element: actuators, gravity, description, link directions and
    lengths, shapes, in gaitopt's own terms (names, m, N m, m/s^2 in gaitopt's world frame)."""

    def __init__(self, r: Reader, elem: ET.Element | None) -> None:
        self.actuators: list[dict[str, Any]] | None = None
        self.gravity: list[float] | None = None
        self.description: str | None = None
        self.shapes: dict[str, dict[str, Any]] = {}
        self.links: dict[str, tuple[str, float]] = {}
        #: The declared symmetry (``<swap kind="link|contact" a=... b=...>``), or None.
        self.symmetry: dict[str, list[list[str]]] | None = None
        if elem is None:
            return
        where = "<gaitopt>"
        if elem.get("version", "1") != "1":
            raise r.fail(f"{where} version", elem.get("version"), "1")
        acts = elem.findall("actuator")
        if acts:
            self.actuators = []
            for a in acts:
                name = r.name(f"{where} <actuator>", a)
                target = {k: a.get(k) for k in ("joint", "contact") if a.get(k) is not None}
                self.actuators.append({
                    "name": name, **target,
                    "limits": [r.number(f"{where} actuator {name!r} lower", a.get("lower")),
                               r.number(f"{where} actuator {name!r} upper", a.get("upper"))]})
        g = elem.find("gravity")
        if g is not None:
            self.gravity = [r.number(f"{where} gravity x", g.get("x")),
                            r.number(f"{where} gravity y", g.get("y"))]
        d = elem.find("description")
        if d is not None:
            self.description = d.text or ""
        for s in elem.findall("shape"):
            link = r.name(f"{where} <shape>", s, "link")
            shape: dict[str, Any] = {"type": s.get("type")}
            if s.get("radius") is not None:
                shape["radius"] = r.number(f"{where} shape {link!r} radius", s.get("radius"))
            self.shapes[link] = shape
        swaps = elem.findall("swap")
        if swaps:
            self.symmetry = {"links": [], "contacts": []}
            for e in swaps:
                kind = e.get("kind")
                if kind not in ("link", "contact"):
                    raise r.fail(f"{where} swap kind", kind, "link or contact")
                pair = [r.name(f"{where} <swap>", e, "a"), r.name(f"{where} <swap>", e, "b")]
                self.symmetry[f"{kind}s"].append(pair)
        for e in elem.findall("link"):
            link = r.name(f"{where} <link>", e)
            direction = e.get("direction")
            if direction not in ("up", "down"):
                raise r.fail(f"{where} link {link!r} direction", direction, "up or down")
            length = r.number(f"{where} link {link!r} length", e.get("length"))
            if not length > 0.0:
                raise r.fail(f"{where} link {link!r} length", length, "a length > 0 (m)")
            self.links[link] = (direction, length)
