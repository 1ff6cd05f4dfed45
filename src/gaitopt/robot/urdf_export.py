"""Writing a :class:`~gaitopt.robot.model.RobotModel` as URDF text (see ``docs/urdf.md``).

gaitopt (x, y) is URDF (x, z); every joint turns about URDF -y, so URDF joint angles, limits
and torques are gaitopt's. :func:`gaitopt.robot.urdf.model_from_urdf` reads the text back to an
equal model.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from gaitopt.robot.errors import ModelError
from gaitopt.robot.model import RobotModel
from gaitopt.robot.urdf_xml import CONTACT_PREFIX


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
        lower, upper = link.joint.limits
        continuous = math.isinf(lower) and math.isinf(upper)  # no bound: a continuous joint
        j = ET.SubElement(robot, "joint", name=link.joint.name,
                          type="continuous" if continuous else "revolute")
        ET.SubElement(j, "parent", link=link.parent)
        ET.SubElement(j, "child", link=link.name)
        ET.SubElement(j, "origin", xyz=_xyz(parent.local_point(*link.joint.at)),
                      rpy="0.0 0.0 0.0")
        ET.SubElement(j, "axis", xyz="0 -1 0")
        attrs = {} if continuous else {"lower": _num(lower), "upper": _num(upper)}  # or inf
        attrs.update(effort=_num(effort.get(link.joint.name, 0.0)), velocity="0.0")
        ET.SubElement(j, "limit", attrs)
        if link.joint.damping:
            ET.SubElement(j, "dynamics", damping=_num(link.joint.damping), friction="0.0")
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
    if model.symmetry is not None:  # a declared symmetry: <swap kind="link|contact" a= b=>
        for kind, pairs in (("link", model.symmetry.links),
                            ("contact", model.symmetry.contacts)):
            for a_name, b_name in pairs:
                ET.SubElement(ext, "swap", kind=kind, a=a_name, b=b_name)
    ET.indent(robot, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"
