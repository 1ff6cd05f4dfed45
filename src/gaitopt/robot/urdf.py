"""URDF import and export: a planar robot in a URDF file <-> a :class:`RobotModel`.

Frames (see ``docs/urdf.md``). URDF's world is x forward, y left, z up; gaitopt's is x
forward, y up, z out of the page. With the common joint axis ``y`` (the default) the sagittal
plane is URDF x-z and

    gaitopt (x, y, z) = URDF (x, z, -y),

so a revolute joint about URDF +y turns the child by ``-q`` in gaitopt's sense (angle, limits
and torque change sign) and a joint about URDF -y (``<axis xyz="0 -1 0"/>``, what the export
writes) needs no flip. With ``axis="x"`` the plane is URDF y-z and gaitopt (x, y, z) = URDF
(-y, z, -x). A gaitopt link frame at zero angle is parallel to the world, so URDF frames
turned by ``rpy`` are re-expressed in that frame (only the rotation about the common axis may
remain between a joint's parent and child for the joint axis to stay normal to the plane).

Import, in short: the root link is the floating base, unless it is a massless link followed
by a floating-base chain (two prismatic joints along x and z and a revolute joint about y
through massless links, a ``planar`` joint or a ``floating`` joint), whose last child is then
the base. Every revolute or continuous joint starts a gaitopt link; a fixed joint merges its
child into its parent (masses, centres of mass and inertias about the common axis combined by
the parallel-axis theorem). Contact points come from fixed joints named
``gaitopt_contact_NAME`` to a massless leaf link NAME (what the export writes) and from
:class:`ContactSpec` arguments (``--contact NAME=LINK:X,Z``). What URDF cannot hold (ground
torques at contact points such as ankles, the order and exact bounds of the actuators,
gravity, the description, each link's direction and length, the shapes inertias came from)
travels in a ``<gaitopt>`` element
inside ``<robot>``, which other URDF readers ignore.

Parser: the XML is read with :mod:`xml.etree.ElementTree`. The maintained PyPI parsers do not
fit: ``yourdfpy`` (0.0.60) pulls in ``trimesh[easy]`` (a mesh stack of a dozen packages) to
read a few XML elements, and silently reads a missing ``ixx``, ``iyy`` or ``izz`` as 1 and a
``<mass>`` without a value as 0, which must be refused here; ``urdf-parser-py`` has had no
release since 2021 (0.0.4). Every problem is a one-line :class:`ModelError` naming the joint
or link.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gaitopt.robot.model import RobotModel, Shape
from gaitopt.robot.schema import INERTIA_RTOL, ModelError, model_from_dict, shape_inertia

__all__ = ["CONTACT_PREFIX", "ContactSpec", "model_from_urdf", "parse_contact_option",
           "urdf_from_model"]

#: Name prefix of the fixed joints that mark contact frames (``gaitopt_contact_tip_1``).
CONTACT_PREFIX = "gaitopt_contact_"
#: Limits (rad) given to a continuous joint: a full turn each way (gaitopt limits are finite).
CONTINUOUS_LIMITS = (-2.0 * math.pi, 2.0 * math.pi)
#: Coordinates smaller than this (m) after a frame rotation are taken as exactly 0.
SNAP = 1e-12
#: Tolerance on a joint axis being the common axis (a unit vector).
AXIS_TOL = 1e-9

#: Rows: gaitopt x, y, z as URDF vectors, for each common axis.
_PLANE = {"y": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
          "x": np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])}
#: Which URDF coordinates of a link frame a ``--contact`` point gives, for each common axis.
_IN_PLANE = {"y": (0, 2, "X,Z"), "x": (1, 2, "Y,Z")}
_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


@dataclass(frozen=True)
class ContactSpec:
    """A contact point to add on import: ``point`` = the two in-plane coordinates (m) in the
    frame of URDF link ``link`` (x, z for the common axis y; y, z for axis x)."""

    name: str
    link: str
    point: tuple[float, float]


def parse_contact_option(text: str) -> ContactSpec:
    """Parse ``NAME=LINK:X,Z`` (e.g. ``tip_1=shank_1:0,-0.5``); ValueError names the form."""
    form = "NAME=LINK:X,Z (e.g. tip_1=shank_1:0,-0.5; X, Z in metres in the link's frame)"
    name, eq, rest = text.partition("=")
    link, colon, coords = rest.rpartition(":")
    parts = coords.split(",")
    try:
        if not (eq and colon and name.strip() and link.strip()) or len(parts) != 2:
            raise ValueError
        x, z = float(parts[0]), float(parts[1])
        if not (math.isfinite(x) and math.isfinite(z)):
            raise ValueError
    except ValueError:
        raise ValueError(f"--contact: got {text!r}; allowed: {form}") from None
    return ContactSpec(name.strip(), link.strip(), (x, z))


# -- reading the XML -------------------------------------------------------------------------

@dataclass
class _ULink:
    name: str
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))      # link frame, m
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # link axes, at com


@dataclass
class _UJoint:
    name: str
    type: str
    parent: str
    child: str
    rot: np.ndarray       # child frame axes in the parent frame (3, 3)
    pos: np.ndarray       # child origin in the parent frame (3,), m
    axis: np.ndarray      # unit vector in the child frame
    limits: tuple[float, float] | None
    effort: float | None


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    """URDF's fixed-axis roll-pitch-yaw: ``Rz(y) Ry(p) Rx(r)``."""
    if r == p == y == 0.0:
        return np.eye(3)
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                              math.cos(y), math.sin(y))
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rz @ ry @ rx


class _Reader:
    """Parses the XML of one URDF; ``source`` names it in errors."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, value: Any, allowed: str, problem: str | None = None) -> ModelError:
        return ModelError(self.source, where, value, allowed, problem=problem)

    def number(self, where: str, text: str | None, default: float | None = None) -> float:
        if text is None:
            if default is None:
                raise self.fail(where, None, "a finite number", problem="missing")
            return default
        try:
            x = float(text)
        except ValueError:
            x = math.nan
        if not math.isfinite(x):
            raise self.fail(where, text, "a finite number")
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
        return _rpy(*rpy), self.vector(f"{where} origin xyz", elem.get("xyz"), (0.0, 0.0, 0.0))

    def name(self, where: str, elem: ET.Element, attr: str = "name") -> str:
        value = elem.get(attr)
        if not value:
            raise self.fail(where, value, f"a non-empty '{attr}' attribute", problem="missing")
        return value

    def link(self, elem: ET.Element) -> _ULink:
        link = _ULink(self.name("<link>", elem))
        where = f"link {link.name!r}"
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

    def joint(self, elem: ET.Element) -> _UJoint:
        name = self.name("<joint>", elem)
        where = f"joint {name!r}"
        kind = elem.get("type")
        if kind not in _JOINT_TYPES:
            raise self.fail(f"{where} type", kind, f"one of {', '.join(_JOINT_TYPES)}")
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
                lo = self.number(f"{where} limit lower", limit.get("lower"), 0.0)
                hi = self.number(f"{where} limit upper", limit.get("upper"), 0.0)
                if lo > hi:
                    raise self.fail(f"{where} limit", f"{lo:g} > {hi:g}", "lower <= upper (rad)")
                limits = (lo, hi)
        if kind == "revolute" and limits is None:
            raise self.fail(f"{where} <limit>", None, "a <limit lower upper effort velocity> "
                            "on a revolute joint (or type continuous)", problem="missing")
        if kind == "continuous":
            limits = CONTINUOUS_LIMITS
        return _UJoint(name, kind, ends[0], ends[1], rot, pos, axis / norm, limits, effort)


# -- import ----------------------------------------------------------------------------------

@dataclass
class _Body:
    """A gaitopt link under construction: URDF links merged by fixed joints."""

    name: str
    parent: int
    joint: dict[str, Any] | None
    effort: float = 0.0
    parts: list[tuple[float, np.ndarray, float]] = field(default_factory=list)  # m, com, I
    points: list[np.ndarray] = field(default_factory=list)  # joints and contacts (plane)


def _read_source(source: str | os.PathLike[str]) -> tuple[str, str]:
    """The URDF text and the name to use in errors."""
    if isinstance(source, str) and source.lstrip().startswith("<"):
        return source, "<string>"
    label = os.fspath(source)
    try:
        return Path(label).read_text("utf-8-sig"), label
    except (OSError, UnicodeDecodeError) as exc:
        detail = getattr(exc, "strerror", None) or str(exc)
        raise ModelError(label, "", label, "a readable URDF file (UTF-8 XML)",
                         problem=f"cannot be read ({detail})") from None


def model_from_urdf(source: str | os.PathLike[str], *, contacts: Iterable[ContactSpec] = (),
                    axis: str = "y", name: str | None = None) -> RobotModel:
    """Read a planar robot from URDF text or a URDF file (see the module docstring).

    Args:
        source: a path, or URDF text (a string starting with ``<``).
        contacts: contact points to add to those the file marks (``gaitopt_contact_*``).
        axis: the common joint axis, ``"y"`` (plane URDF x-z) or ``"x"`` (plane URDF y-z).
        name: the model name (default: the robot's name).

    Raises:
        ModelError: one line naming the file, the joint or link and what is allowed.
    """
    text, label = _read_source(source)
    if axis not in _PLANE:
        raise ModelError(label, "axis", axis, "y or x (the common joint axis)")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ModelError(label, "", "(XML text)", "well-formed XML",
                         problem=f"not valid XML: {exc}") from None
    if root.tag != "robot":
        raise ModelError(label, "", f"<{root.tag}>", "a <robot> element",
                         problem=f"the root element is <{root.tag}>")
    return _Importer(_Reader(label), root, _PLANE[axis], axis).model(list(contacts), name)


class _Importer:
    def __init__(self, reader: _Reader, root: ET.Element, plane: np.ndarray, axis: str) -> None:
        self.r, self.plane, self.axis = reader, plane, axis
        self.links: dict[str, _ULink] = {}
        for elem in root.findall("link"):
            link = reader.link(elem)
            if link.name in self.links:
                raise reader.fail(f"link {link.name!r}", link.name, "unique link names",
                                  problem="a second link of this name")
            self.links[link.name] = link
        self.joints = [reader.joint(e) for e in root.findall("joint")]
        joint_names: set[str] = set()
        for j in self.joints:
            if j.name in joint_names:
                raise reader.fail(f"joint {j.name!r}", j.name, "unique joint names",
                                  problem="a second joint of this name")
            joint_names.add(j.name)
        self.extension = root.find("gaitopt")
        self.robot_name = root.get("name") or "robot"
        self.parent_joint: dict[str, _UJoint] = {}
        self.children: dict[str, list[_UJoint]] = {n: [] for n in self.links}
        for j in self.joints:
            for end in (j.parent, j.child):
                if end not in self.links:
                    raise reader.fail(f"joint {j.name!r}", end, "the name of a <link> of this "
                                      "robot", problem=f"no link {end!r}")
            if j.child in self.parent_joint:
                other = self.parent_joint[j.child].name
                raise reader.fail(f"joint {j.name!r}", j.child, "a tree: one parent joint per "
                                  "link", problem=f"link {j.child!r} already has parent joint "
                                  f"{other!r} (a closed loop or a second parent)")
            self.parent_joint[j.child] = j
            self.children[j.parent].append(j)
        roots = [n for n in self.links if n not in self.parent_joint]
        if len(roots) > 1:
            raise reader.fail("", roots, "one root link and a tree of joints",
                              problem=f"{len(roots)} links without a parent "
                                      f"({', '.join(roots)})")
        seen, todo = set(), roots[:1]
        while todo:
            n = todo.pop()
            seen.add(n)
            todo.extend(j.child for j in self.children[n])
        if len(seen) != len(self.links):  # a link outside the tree is on a loop of parents
            path = [next(n for n in self.links if n not in seen)]
            while (up := self.parent_joint[path[-1]].parent) not in path:
                path.append(up)
            loop = [*path[path.index(up):], up][::-1]
            joints = [self.parent_joint[n].name for n in loop[1:]]
            raise reader.fail(f"joint {joints[0]!r}", loop, "a tree of joints from one root "
                              "link", problem=f"a closed loop of links {' -> '.join(loop)} "
                              f"(joints {', '.join(joints)})")
        self.root = roots[0]

    # -- frames ------------------------------------------------------------------------------
    def in_plane(self, v: np.ndarray) -> np.ndarray:
        """gaitopt (x, y) of a URDF vector given in a body's (world-parallel) frame."""
        return self.plane[:2] @ v

    def about_normal(self, where: str, v: np.ndarray) -> float:
        """+1 if the unit vector ``v`` is gaitopt's +z, -1 if -z; else a ModelError."""
        g = self.plane @ v
        if abs(abs(g[2]) - 1.0) > AXIS_TOL:
            raise self.r.fail(where, " ".join(f"{x:.6g}" for x in v), f"an axis along "
                              f"+-{self.axis} (the common joint axis; the robot is planar)")
        return 1.0 if g[2] > 0 else -1.0

    def base_chain(self) -> tuple[str, list[_UJoint]]:
        """The base link and the floating-base joints above it (see the module docstring)."""
        cur = self.root
        chain: list[_UJoint] = []
        while self.links[cur].mass == 0.0 and len(self.children[cur]) == 1:
            j = self.children[cur][0]
            kinds = [c.type for c in chain]
            if j.type in ("fixed", "prismatic", "planar", "floating") or (
                    j.type in ("revolute", "continuous") and "prismatic" in kinds):
                chain.append(j)
                cur = j.child
                if j.type in ("revolute", "continuous", "planar", "floating"):
                    break
            else:
                break
        moving = [j for j in chain if j.type != "fixed"]
        rot = np.eye(3)
        allowed = (f"a floating base of two prismatic joints (along x and z) and a revolute "
                   f"joint about {self.axis} through massless links, a planar or a floating "
                   "joint, at the root")
        for j in chain:
            rot = rot @ j.rot
            world_axis = rot @ j.axis
            if j.type == "planar":
                self.about_normal(f"joint {j.name!r} axis (the plane normal)", world_axis)
            elif j.type in ("revolute", "continuous"):
                self.about_normal(f"joint {j.name!r} axis", world_axis)
        if moving and moving[0].type == "prismatic":
            directions = sorted(int(np.argmax(np.abs(self.plane @ (r @ j.axis))))
                                for j, r in self._chain_rotations(chain) if j.type == "prismatic")
            if [j.type for j in moving][-1] not in ("revolute", "continuous") or \
                    len(moving) != 3 or directions != [0, 1]:
                raise self.r.fail(f"joint {moving[0].name!r}", moving[0].type, allowed,
                                  problem="an incomplete floating-base chain")
            for j, r in self._chain_rotations(chain):
                g = self.plane @ (r @ j.axis)
                if j.type == "prismatic" and abs(np.max(np.abs(g)) - 1.0) > AXIS_TOL:
                    raise self.r.fail(f"joint {j.name!r} axis", j.axis.tolist(),
                                      "a prismatic axis along x or z of the world")
        for name in [j.child for j in chain[:-1]] + ([self.root] if chain else []):
            if self.links[name].mass != 0.0:
                raise self.r.fail(f"link {name!r}", self.links[name].mass, "massless links in "
                                  "the floating-base chain", problem="a link with mass")
        self.base_rot = rot
        return cur, chain

    @staticmethod
    def _chain_rotations(chain: list[_UJoint]) -> list[tuple[_UJoint, np.ndarray]]:
        out, rot = [], np.eye(3)
        for j in chain:
            rot = rot @ j.rot
            out.append((j, rot))
        return out

    # -- the model ---------------------------------------------------------------------------
    def model(self, specs: list[ContactSpec], name: str | None) -> RobotModel:
        base, chain = self.base_chain()
        bodies = [_Body(base, -1, None)]
        frame = {base: (0, self.base_rot, np.zeros(3))}  # link -> body, axes, origin (body)
        contacts: list[tuple[str, int, np.ndarray]] = []
        done = {j.name for j in chain}
        pending = [j for j in self.joints if j.name not in done]
        while pending:
            ready = [j for j in pending if j.parent in frame]
            if not ready:  # only links of the base chain are left as parents
                j = pending[0]
                raise self.r.fail(f"joint {j.name!r}", j.parent, "joints below the base link",
                                  problem=f"a joint on the floating-base chain link {j.parent!r}")
            j = ready[0]
            pending.remove(j)
            k, rot_p, pos_p = frame[j.parent]
            rot, pos = rot_p @ j.rot, pos_p + rot_p @ j.pos
            where = f"joint {j.name!r}"
            if j.type == "fixed":
                child = self.links[j.child]
                if (j.name.startswith(CONTACT_PREFIX) and child.mass == 0.0
                        and not self.children[j.child]):
                    contacts.append((j.child, k, self.in_plane(pos)))
                frame[j.child] = (k, rot, pos)
            elif j.type in ("revolute", "continuous"):
                sign = self.about_normal(f"{where} axis", rot @ j.axis)
                assert j.limits is not None
                lo, hi = (j.limits if sign > 0 else (-j.limits[1] + 0.0, -j.limits[0] + 0.0))
                at = self.in_plane(pos)
                bodies[k].points.append(at)
                bodies.append(_Body(j.child, k, {"name": j.name, "at": at, "limits": [lo, hi]},
                                    effort=j.effort or 0.0))
                frame[j.child] = (len(bodies) - 1, rot, np.zeros(3))
            else:
                raise self.r.fail(where, j.type, "revolute, continuous or fixed joints below "
                                  "the base (prismatic, planar and floating joints only in the "
                                  "floating-base chain at the root)",
                                  problem=f"a {j.type} joint outside the floating-base chain")
        normal = -self.plane[2]
        for link_name, (k, rot, pos) in frame.items():
            link = self.links[link_name]
            if link.mass > 0.0:
                inertia = float(normal @ rot @ link.inertia @ rot.T @ normal)
                bodies[k].parts.append((link.mass, self.in_plane(pos + rot @ link.com), inertia))
        taken = {c[0] for c in contacts}
        for spec in specs:
            if spec.name in taken:
                raise self.r.fail(f"contact {spec.name!r}", spec.name, "a contact name not "
                                  "used by another contact", problem="a duplicate contact name")
            if spec.link not in frame:
                raise self.r.fail(f"contact {spec.name!r}", spec.link,
                                  "the name of a link at or below the base link "
                                  f"({', '.join(sorted(frame))})", problem=f"no link "
                                  f"{spec.link!r}")
            k, rot, pos = frame[spec.link]
            local = np.zeros(3)
            i0, i1, _ = _IN_PLANE[self.axis]
            local[i0], local[i1] = spec.point
            contacts.append((spec.name, k, self.in_plane(pos + rot @ local)))
            taken.add(spec.name)
        for _, k, p in contacts:
            bodies[k].points.append(p)
        return model_from_dict(self.to_dict(bodies, contacts, name), source=self.r.source)

    def to_dict(self, bodies: list[_Body], contacts: list[tuple[str, int, np.ndarray]],
                name: str | None) -> dict[str, Any]:
        ext = _Extension(self.r, self.extension)
        links: list[dict[str, Any]] = []
        for i, b in enumerate(bodies):
            mass = sum(m for m, _, _ in b.parts)
            if not mass > 0.0:
                raise self.r.fail(f"link {b.name!r}", 0.0, "a mass > 0 on every gaitopt link "
                                  "(the base, or a URDF link after a revolute joint, with the "
                                  "links fixed to it)", problem="no mass")
            com = (b.parts[0][1] if len(b.parts) == 1 else
                   sum((m * c for m, c, _ in b.parts), np.zeros(2)) / mass)
            inertia = sum(i_ + m * float(np.sum((c - com) ** 2)) for m, c, i_ in b.parts)
            if not inertia > 0.0:
                raise self.r.fail(f"link {b.name!r}", inertia, "an inertia > 0 about the "
                                  f"{self.axis} axis (kg m^2)")
            direction, length = ext.links.get(b.name) or _direction_and_length(
                b.points, com, base=i == 0)
            entry: dict[str, Any] = {"name": b.name,
                                     "parent": None if b.parent < 0 else bodies[b.parent].name}
            if b.joint is not None:
                entry["joint"] = {**b.joint, "at": _point(b.joint["at"], direction)}
            entry.update({"direction": direction, "length": length, "mass": mass,
                          "com": _point(com, direction), "inertia": inertia})
            shape = ext.shapes.get(b.name)
            if shape is not None:
                s = Shape(type=shape["type"], radius=shape.get("radius"))
                expected = shape_inertia(s, mass, length)
                if abs(expected - inertia) <= INERTIA_RTOL * expected:
                    entry["shape"] = shape
            links.append(entry)
        directions = {b.name: links[i]["direction"] for i, b in enumerate(bodies)}
        data: dict[str, Any] = {
            "name": name or self.robot_name, "links": links,
            "contacts": [{"name": c, "link": bodies[k].name, "at": _point(p, directions[
                bodies[k].name])} for c, k, p in contacts],
        }
        if ext.actuators is not None:
            data["actuators"] = ext.actuators
        else:
            data["actuators"] = [
                {"name": b.joint["name"], "joint": b.joint["name"], "limits": [-b.effort,
                                                                               b.effort]}
                for b in bodies if b.joint is not None and b.effort > 0.0]
        if ext.gravity is not None:
            data["gravity"] = ext.gravity
        if ext.description is not None:
            data["description"] = ext.description
        return data


def _clean(x: float) -> float:
    """``x`` with ``-0.0`` and rounding dust (``|x| < SNAP``) made ``0.0``."""
    return 0.0 if abs(x) < SNAP else float(x)


def _point(p: Sequence[float] | np.ndarray, direction: str) -> list[float]:
    """gaitopt link-frame coordinates (x, y) as ``[along, across]`` for a link direction."""
    x, y = float(p[0]), float(p[1])
    return [_clean(-y), _clean(x)] if direction == "down" else [_clean(y), _clean(-x)]


def _direction_and_length(points: list[np.ndarray], com: np.ndarray,
                          base: bool) -> tuple[str, float]:
    """The documented rule (``docs/urdf.md``) for a link's axis and length.

    ``points`` are the link's child joints and contact points and ``com`` its centre of mass,
    as gaitopt (x, y) in the link frame at zero angle. A non-base link points ``down`` to its
    lowest point below the origin (length: that depth), else ``up`` to its highest point above
    it. The base, and a link whose points are all level with its origin, points towards its
    centre of mass (``up`` if above the origin) with length twice the centre's height (the
    centre in the middle), at least reaching its points on that side; a link with nothing
    above or below its origin gets ``down`` and 1 m.
    """
    below = max([-float(p[1]) for p in points if _clean(p[1]) < 0.0], default=0.0)
    above = max([float(p[1]) for p in points if _clean(p[1]) > 0.0], default=0.0)
    height = _clean(float(com[1]))
    if not base or height == 0.0:
        if below > 0.0:
            return "down", below
        if above > 0.0:
            return "up", above
    if height > 0.0:
        return "up", max(2.0 * height, above)
    if height < 0.0:
        return "down", max(-2.0 * height, below)
    return "down", 1.0


class _Extension:
    """The ``<gaitopt>`` element: actuators, gravity, description, link directions and
    lengths, shapes, in gaitopt's own terms (names, m, N m, m/s^2 in gaitopt's world frame)."""

    def __init__(self, r: _Reader, elem: ET.Element | None) -> None:
        self.actuators: list[dict[str, Any]] | None = None
        self.gravity: list[float] | None = None
        self.description: str | None = None
        self.shapes: dict[str, dict[str, Any]] = {}
        self.links: dict[str, tuple[str, float]] = {}
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
        for e in elem.findall("link"):
            link = r.name(f"{where} <link>", e)
            direction = e.get("direction")
            if direction not in ("up", "down"):
                raise r.fail(f"{where} link {link!r} direction", direction, "up or down")
            length = r.number(f"{where} link {link!r} length", e.get("length"))
            if not length > 0.0:
                raise r.fail(f"{where} link {link!r} length", length, "a length > 0 (m)")
            self.links[link] = (direction, length)


# -- export ----------------------------------------------------------------------------------

def _num(x: float) -> str:
    return repr(float(x) + 0.0)  # shortest text that reads back to the same float; no -0.0


def _xyz(p: tuple[float, float]) -> str:
    """A gaitopt point (x, y) in a link frame as URDF ``xyz`` (plane x-z, y = 0)."""
    return f"{_num(p[0])} 0.0 {_num(p[1])}"


def urdf_from_model(model: RobotModel) -> str:
    """The model as URDF text (see ``docs/urdf.md``); ``model_from_urdf`` reads it back.

    The base is the root link (no world link: give your simulator a planar root joint). Joint
    axes are URDF -y, so URDF joint angles, limits and torques equal gaitopt's. Link inertias:
    ``iyy`` is the model's inertia; ``ixx`` and ``izz`` are those of the link's ellipsoid
    (``shape``) or else equal to ``iyy`` (they do not enter planar motion). Contact points are
    massless links joined by fixed joints ``gaitopt_contact_NAME``; joint efforts are the
    largest bound of the joint's actuator (0: none; ``velocity="0.0"``: gaitopt has no
    velocity limit, URDF requires the attribute); the exact actuators, gravity, description,
    link directions and lengths and shapes are in a ``<gaitopt>`` element.
    """
    robot = ET.Element("robot", name=model.name)
    robot.append(ET.Comment(
        f" written by gaitopt from the model {model.name!r}. Frames: gaitopt (x, y) = URDF "
        "(x, z); joints turn about URDF -y, so their angles, limits and torques are gaitopt's. "
        f"The root link {model.base.name!r} is the floating base (no world link). "))
    names = [link.name for link in model.links] + [c.name for c in model.contacts]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise ModelError(model.name, "contacts", dup, "contact names that are not link names "
                         "(URDF links share one namespace)", problem=f"{dup!r} names a link "
                         "and a contact point")
    effort: dict[str, float] = {}
    for a in model.actuators:
        if a.joint is not None:
            effort[a.joint] = max(abs(a.limits[0]), abs(a.limits[1]))
    for link in model.links:
        elem = ET.SubElement(robot, "link", name=link.name)
        inertial = ET.SubElement(elem, "inertial")
        ET.SubElement(inertial, "origin", xyz=_xyz(link.com_local), rpy="0.0 0.0 0.0")
        ET.SubElement(inertial, "mass", value=_num(link.mass))
        along = link.inertia  # about the link axis (URDF z), out-of-plane
        if link.shape is not None and link.shape.type == "ellipsoid":
            assert link.shape.radius is not None
            along = 2.0 * link.mass * link.shape.radius ** 2 / 5.0
        ET.SubElement(inertial, "inertia", ixx=_num(link.inertia), ixy="0.0", ixz="0.0",
                      iyy=_num(link.inertia), iyz="0.0", izz=_num(along))
    for link in model.links[1:]:
        assert link.joint is not None and link.parent is not None
        parent = model.link(link.parent)
        j = ET.SubElement(robot, "joint", name=link.joint.name, type="revolute")
        ET.SubElement(j, "parent", link=link.parent)
        ET.SubElement(j, "child", link=link.name)
        ET.SubElement(j, "origin", xyz=_xyz(parent.local_point(*link.joint.at)),
                      rpy="0.0 0.0 0.0")
        ET.SubElement(j, "axis", xyz="0 -1 0")
        ET.SubElement(j, "limit", lower=_num(link.joint.limits[0]),
                      upper=_num(link.joint.limits[1]),
                      effort=_num(effort.get(link.joint.name, 0.0)), velocity="0.0")
    for c in model.contacts:
        robot.append(ET.Comment(f" gaitopt contact point {c.name!r} on {c.link!r} "))
        ET.SubElement(robot, "link", name=c.name)
        j = ET.SubElement(robot, "joint", name=CONTACT_PREFIX + c.name, type="fixed")
        ET.SubElement(j, "parent", link=c.link)
        ET.SubElement(j, "child", link=c.name)
        ET.SubElement(j, "origin", xyz=_xyz(model.link(c.link).local_point(*c.at)),
                      rpy="0.0 0.0 0.0")
    robot.append(ET.Comment(" what URDF has no place for, in gaitopt's terms (docs/urdf.md) "))
    ext = ET.SubElement(robot, "gaitopt", version="1")
    ET.SubElement(ext, "gravity", x=_num(model.gravity[0]), y=_num(model.gravity[1]))
    ET.SubElement(ext, "description").text = model.description
    for link in model.links:
        ET.SubElement(ext, "link", name=link.name, direction=link.direction,
                      length=_num(link.length))
    for link in model.links:
        if link.shape is not None:
            attrs = {"link": link.name, "type": link.shape.type}
            if link.shape.radius is not None:
                attrs["radius"] = _num(link.shape.radius)
            ET.SubElement(ext, "shape", attrs)
    for a in model.actuators:
        target = {"joint": a.joint} if a.joint is not None else {"contact": a.contact or ""}
        ET.SubElement(ext, "actuator", {"name": a.name, **target, "lower": _num(a.limits[0]),
                                        "upper": _num(a.limits[1])})
    ET.indent(robot, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"

