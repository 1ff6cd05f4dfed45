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
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gaitopt.robot.contact_inference import Shape, infer_contacts
from gaitopt.robot.errors import ModelError
from gaitopt.robot.model import RobotModel
from gaitopt.robot.schema import DEFAULT_GRAVITY, model_from_dict
from gaitopt.robot.urdf_assumptions import (
    Actuated,
    actuators_from_urdf,
    base_note,
    declare_foot_symmetry,
    default_bound,
    symmetry_note,
)
from gaitopt.robot.urdf_bodies import Body, model_data, standing
from gaitopt.robot.urdf_collision import planar_shape
from gaitopt.robot.urdf_export import urdf_from_model
from gaitopt.robot.urdf_plane import (
    AXIS_TOL,
    IN_PLANE,
    PLANE,
    SNAP,
    is_identity,
)
from gaitopt.robot.urdf_xml import (
    CONTACT_PREFIX,
    Extension,
    Reader,
    UJoint,
    ULink,
    transmission_joints,
)

__all__ = ["CONTACT_PREFIX", "ContactSpec", "UrdfImport", "import_urdf", "model_from_urdf",
           "parse_contact_option", "urdf_from_model"]

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


# -- import ----------------------------------------------------------------------------------

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


@dataclass(frozen=True)
class UrdfImport:
    """A URDF import: the model, and what the import assumed (:meth:`lines`)."""

    model: RobotModel
    notes: tuple[str, ...]

    def lines(self) -> list[str]:
        """What the import assumed, one topic a line (a topic may add indented lines): the
        floating base, the links merged, the actuators, the contacts, the symmetry; a line
        starting ``warning:`` for a choice the file did not make (a torque bound)."""
        return list(self.notes)


def model_from_urdf(source: str | os.PathLike[str], *, contacts: Iterable[ContactSpec] = (),
                    axis: str = "y", name: str | None = None) -> RobotModel:
    """Read a planar robot from URDF text or a URDF file: :func:`import_urdf`'s model."""
    return import_urdf(source, contacts=contacts, axis=axis, name=name).model


def import_urdf(source: str | os.PathLike[str], *, contacts: Iterable[ContactSpec] = (),
                axis: str = "y", name: str | None = None) -> UrdfImport:
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
    if axis not in PLANE:
        raise ModelError(label, "axis", axis, "y or x (the common joint axis)")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ModelError(label, "", "(XML text)", "well-formed XML",
                         problem=f"not valid XML: {exc}") from None
    if root.tag != "robot":
        raise ModelError(label, "", f"<{root.tag}>", "a <robot> element",
                         problem=f"the root element is <{root.tag}>")
    return _Importer(Reader(label), root, PLANE[axis], axis).run(list(contacts), name)


class _Importer:
    def __init__(self, reader: Reader, root: ET.Element, plane: np.ndarray, axis: str) -> None:
        self.r, self.plane, self.axis = reader, plane, axis
        self.links: dict[str, ULink] = {}
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
        self.transmissions = transmission_joints(reader, root)
        self.robot_name = root.get("name") or "robot"
        self.parent_joint: dict[str, UJoint] = {}
        self.children: dict[str, list[UJoint]] = {n: [] for n in self.links}
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
        if not self.links:
            raise reader.fail("", None, "a <robot> with <link> elements", problem="no links")
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
    def in_plane(self, v: np.ndarray, exact: bool) -> np.ndarray:
        """gaitopt (x, y) of a URDF vector given in a body's (world-parallel) frame; unless
        ``exact`` (no rotation went into ``v``), rounding dust (``|x| < SNAP``) becomes 0."""
        g = self.plane[:2] @ v + 0.0
        return g if exact else np.where(np.abs(g) < SNAP, 0.0, g)

    def about_normal(self, where: str, v: np.ndarray) -> float:
        """+1 if the unit vector ``v`` is gaitopt's +z, -1 if -z; else a ModelError."""
        g = self.plane @ v
        if abs(abs(g[2]) - 1.0) > AXIS_TOL:
            raise self.r.fail(where, " ".join(f"{x:.6g}" for x in v), f"an axis along "
                              f"+-{self.axis} (the common joint axis; the robot is planar)")
        return 1.0 if g[2] > 0 else -1.0

    def base_chain(self) -> tuple[str, list[UJoint]]:
        """The base link and the floating-base joints above it (see the module docstring)."""
        cur = self.root
        chain: list[UJoint] = []
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
        rot, prismatic = np.eye(3), []
        for j in chain:
            rot = rot @ j.rot
            world_axis = rot @ j.axis  # a joint axis is given in the child frame
            if j.type == "planar":
                self.about_normal(f"joint {j.name!r} axis (the plane normal)", world_axis)
            elif j.type in ("revolute", "continuous"):
                self.about_normal(f"joint {j.name!r} axis", world_axis)
            elif j.type == "prismatic":
                prismatic.append(np.abs(self.plane @ world_axis))
        # the walk takes revolute joints only after a prismatic one, and stops after them
        if prismatic and not (len(moving) == 3 and moving[-1].type != "prismatic" and sorted(
                int(np.argmax(g)) for g in prismatic) == [0, 1] and all(
                abs(float(np.max(g)) - 1.0) <= AXIS_TOL for g in prismatic)):
            raise self.r.fail(f"joint {moving[0].name!r}", moving[0].type,
                              "a floating base of two prismatic joints (along x and z) and a "
                              f"revolute joint about {self.axis} through massless links, a "
                              "planar or a floating joint, at the root",
                              problem="an incomplete floating-base chain")
        self.base_rot = rot
        return cur, chain

    # -- the model ---------------------------------------------------------------------------
    def run(self, specs: list[ContactSpec], name: str | None) -> UrdfImport:
        base, chain = self.base_chain()
        bodies = [Body(base, -1, None)]
        # URDF link -> (its gaitopt link, its axes and origin in that link's frame, whether
        # no rotation went into them: then points computed from them are exact)
        frame = {base: (0, self.base_rot, np.zeros(3), is_identity(self.base_rot))}
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
            k, rot_p, pos_p, exact_p = frame[j.parent]
            rot, pos = rot_p @ j.rot, pos_p + rot_p @ j.pos
            where = f"joint {j.name!r}"
            if j.type == "fixed":
                child = self.links[j.child]
                if (j.name.startswith(CONTACT_PREFIX) and child.mass == 0.0
                        and not self.children[j.child]):
                    contacts.append((j.child, k, self.in_plane(pos, exact_p)))
                frame[j.child] = (k, rot, pos, exact_p and is_identity(rot))
            elif j.type in ("revolute", "continuous"):
                sign = self.about_normal(f"{where} axis", rot @ j.axis)
                assert j.limits is not None
                lo, hi = (j.limits if sign > 0 else (-j.limits[1] + 0.0, -j.limits[0] + 0.0))
                at = self.in_plane(pos, exact_p)
                bodies[k].points.append(at)
                joint: dict[str, Any] = {"name": j.name, "at": at, "limits": [lo, hi]}
                if j.damping:
                    joint["damping"] = j.damping
                bodies.append(Body(j.child, k, joint, effort=j.effort or 0.0))
                frame[j.child] = (len(bodies) - 1, rot, np.zeros(3), is_identity(rot))
            else:
                raise self.r.fail(where, j.type, "revolute, continuous or fixed joints below "
                                  "the base (prismatic, planar and floating joints only in the "
                                  "floating-base chain at the root)",
                                  problem=f"a {j.type} joint outside the floating-base chain")
        normal = -self.plane[2]
        for link_name, (k, rot, pos, exact) in frame.items():
            link = self.links[link_name]
            if link.mass > 0.0:
                inertia = float(normal @ rot @ link.inertia @ rot.T @ normal)
                com = self.in_plane(pos + rot @ link.com, exact)
                bodies[k].parts.append((link.mass, com, inertia))
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
            k, rot, pos, exact = frame[spec.link]
            local = np.zeros(3)
            i0, i1 = IN_PLANE[self.axis]
            local[i0], local[i1] = spec.point
            contacts.append((spec.name, k, self.in_plane(pos + rot @ local, exact)))
            taken.add(spec.name)
        ext = Extension(self.r, self.extension)
        marked = [c for c, _, _ in contacts if c not in {spec.name for spec in specs}]
        merged = {b.name: [u for u, (k, _, _, _) in frame.items()
                           if k == i and u != b.name and u not in marked]
                  for i, b in enumerate(bodies)}
        notes = [base_note(base, chain, ("x", "y", base), merged[base])]
        fixed = [f"{u} -> {b}" for b, us in merged.items() if b != base for u in us]
        if fixed:
            notes.append(f"links fixed to others (merged, or dropped if massless): "
                         f"{', '.join(fixed)}")
        inferred = None
        unused: list[str] = []
        if not contacts:
            draft = model_from_dict(model_data(bodies, [], name or self.robot_name, ext),
                                    source=self.r.source)
            shapes, unused = self.shapes(frame, bodies)
            inferred = infer_contacts(draft, shapes, source=self.r.source)
            for c in inferred.contacts:
                k = draft.link_index(c.link)
                contacts.append((c.name, k, np.array(draft.link(c.link).local_point(*c.at))))
        for _, k, p in contacts:
            bodies[k].points.append(p)
        data = model_data(bodies, contacts, name or self.robot_name, ext)
        data["actuators"], actuator_notes = self.actuators(bodies, ext)
        if ext.symmetry is not None:
            data["symmetry"] = ext.symmetry
        notes.extend(actuator_notes)
        if inferred is None:
            how = [f"{', '.join(marked)} from the frames {CONTACT_PREFIX}NAME"] if marked else []
            if specs:
                how.append(f"{', '.join(spec.name for spec in specs)} from --contact")
            notes.append(f"contacts: {'; '.join(how)}")
        elif not inferred.contacts:
            notes.append("contacts: none (no collision shape on a leaf link; give them with "
                         "--contact NAME=LINK:X,Z)")
            notes.extend(f"  {line}" for line in unused)
        else:
            notes.append(f"contacts: {', '.join(c for c, _, _ in contacts)} (inferred from "
                         "the collision shapes at the standing pose; --contact overrides):")
            notes.extend(f"  {line}" for line in [*inferred.lines(), *unused])
            if ext.symmetry is None:
                declare_foot_symmetry(data, source=self.r.source)
        model = model_from_dict(data, source=self.r.source)
        notes.append(symmetry_note(model, by_import=ext.symmetry is None
                                   and model.symmetry is not None))
        return UrdfImport(model, tuple(notes))

    def shapes(self, frame: dict[str, tuple[int, np.ndarray, np.ndarray, bool]],
               bodies: list[Body]) -> tuple[list[Shape], list[str]]:
        """The collision shapes of the URDF links that make up leaf gaitopt links, in the
        gaitopt link's frame (only feet matter: a shape elsewhere, even one tilted out of the
        plane, is not read), and lines for what was not used."""
        parents = {b.parent for b in bodies}
        out, meshes, elsewhere = [], [], []
        for link_name, (k, rot, pos, _) in frame.items():
            for c in self.links[link_name].collisions:
                if k in parents:
                    elsewhere.append(link_name)
                    continue
                shape = planar_shape(c, link=bodies[k].name, urdf_link=link_name, rot=rot,
                                     pos=pos, plane=self.plane, source=self.r.source)
                if shape is None:
                    meshes.append(link_name)
                else:
                    out.append(shape)
        notes = []
        if meshes:
            notes.append(f"meshes are not read (no contact from them): "
                         f"{', '.join(dict.fromkeys(meshes))}")
        if elsewhere:
            notes.append(f"shapes on links that are not leaves are not feet: "
                         f"{', '.join(dict.fromkeys(elsewhere))}")
        return out, notes

    def actuators(self, bodies: list[Body], ext: Extension) -> tuple[list[dict[str, Any]],
                                                                   list[str]]:
        """The actuators (model-file entries) and the lines that say where they came from."""
        if ext.actuators is not None:
            return ext.actuators, [f"actuators: {', '.join(a['name'] for a in ext.actuators)} "
                                   "(from the <gaitopt> element)"]
        joints = [Actuated(b.joint["name"], b.effort) for b in bodies if b.joint is not None]
        gravity = math.hypot(*(ext.gravity or DEFAULT_GRAVITY))
        return actuators_from_urdf(joints, self.transmissions,
                                   default_bound(*standing(bodies), gravity), reader=self.r,
                                   urdf_joints={j.name: j for j in self.joints})
