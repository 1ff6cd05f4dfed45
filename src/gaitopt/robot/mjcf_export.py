"""Writing a :class:`~gaitopt.robot.model.RobotModel` as MuJoCo MJCF text (``docs/simulate.md``).

Frames follow the URDF export (``docs/urdf.md``): gaitopt (x, y, z) = MuJoCo (x, z, -y), the
sagittal plane is MuJoCo's x-z plane. The floating base is a body with three root joints,

* ``rootx`` (slide along x) and ``rootz`` (slide along z): gaitopt's base position (x, y), m,
  since the base body sits at the origin (``pos="0 0 0"``);
* ``rooty`` (hinge about **+y**, MuJoCo's usual planar root, as Gymnasium's Walker2d): the
  base angle is ``angle = -rooty``;

and every gaitopt joint is a hinge about **-y**, so its angle, limits and torque are gaitopt's.
So ``qpos = (x, y, -angle, q_joints...)`` and the same for ``qvel``, the joints in MuJoCo's
depth-first order of the body tree (gaitopt's order of ``q`` when every link follows its
parent's subtree, as in the built-in models; :class:`gaitopt.analysis.mujoco_model.
CoordinateMap` maps by name in general).

Each link is a body whose frame is the gaitopt link frame (its origin the proximal joint,
parallel to the world at zero angle, so no rotations appear), with an ``<inertial>`` of the
link's mass, centre of mass and inertia: ``iyy`` (about MuJoCo y, the plane's normal) is the
model's inertia; ``ixx`` and ``izz`` do not enter planar motion and get positive values, those
of the URDF export (the link's ellipsoid if it has a ``shape``, else ``iyy``). The compiler
does not compute inertias from geoms (``inertiafromgeom="false"``); the capsules drawn along
the links are massless and collide with nothing.

Each contact point is a sphere of radius ``r`` (:class:`MjcfContact`) centred **at** the point,
and the ground plane lies ``r`` below gaitopt's ground (at MuJoCo ``z = -r``): a sphere touches
the plane exactly when its centre, the contact point, is at gaitopt height 0, whatever the
link's angle. Only the spheres and the plane collide (the spheres have ``contype 0``,
``conaffinity 1``, the plane both 1: a swing tip passes the stance tip). Joint actuators are
motors (gear 1, ``ctrlrange`` the actuator's torque bounds, N m). Contact actuators (the
five-link model's ankles: a torque between the ground and the link while the point is on the
ground) are not joints and have no MJCF element; a comment lists them
(:mod:`gaitopt.analysis.simulate` applies them as external torques).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

from gaitopt.robot.errors import ModelError
from gaitopt.robot.model import Link, RobotModel

#: Names of the three root joints, in the order of gaitopt's base coordinates (x, y, angle).
ROOT_JOINTS: tuple[str, str, str] = ("rootx", "rootz", "rooty")


@dataclass(frozen=True, kw_only=True)
class MjcfContact:
    """Contact and integration settings written into the MJCF.

    ``radius`` of the contact spheres (m); ``friction``: the sliding friction coefficient of
    the sphere-plane contacts (MuJoCo takes the larger of the two geoms'; both get it);
    ``solref = (timeconst s, dampratio)`` and ``solimp = (dmin, dmax, width m)``: MuJoCo's soft
    contact (a stiff, critically damped contact: impacts are nearly inelastic, as gaitopt's;
    MuJoCo wants ``timeconst >= 2 timestep``; a softer 4 ms contact at 0.5 ms steps delayed
    the seven-link walk's heel strikes by up to 0.16 s from the fourth step on, while this
    one keeps its step time to 3 ms);
    ``timestep`` (s) and ``integrator`` of the simulation (``implicitfast`` treats the
    actuators' velocity feedback implicitly, so stiff PD gains stay stable).
    """

    radius: float = 0.005
    friction: float = 1.0
    solref: tuple[float, float] = (0.002, 1.0)
    solimp: tuple[float, float, float] = (0.95, 0.99, 0.001)
    timestep: float = 0.00025
    integrator: str = "implicitfast"

    def describe(self) -> str:
        """One line for people."""
        return (f"contact spheres r = {self.radius * 1000:g} mm (ground plane r below), "
                f"friction {self.friction:g}, solref {_nums(self.solref)}, "
                f"solimp {_nums(self.solimp)}, condim 3, timestep {self.timestep * 1000:g} ms, "
                f"{self.integrator}")


def _num(x: float) -> str:
    return repr(float(x) + 0.0)  # shortest text that reads back to the same float; no -0.0


def _nums(values: tuple[float, ...]) -> str:
    return " ".join(_num(v) for v in values)


#: The least mass (kg) and inertia (kg m^2) MuJoCo's compiler gives a body of the export
#: (``<compiler boundmass boundinertia>``): MuJoCo refuses a moving body without either.
BOUND_MASS = 1e-12
BOUND_INERTIA = 1e-12


def _xyz(p: tuple[float, float]) -> str:
    """A gaitopt point (x, y) in a link frame as MuJoCo ``pos`` (plane x-z, y = 0)."""
    return f"{_num(p[0])} 0.0 {_num(p[1])}"


def _out_of_plane(link: Link) -> tuple[float, float]:
    """``(ixx, izz)``: positive inertias about the in-plane axes (no effect on planar motion):
    the link's ellipsoid about its axis for ``izz``, else the in-plane inertia itself."""
    along = link.inertia
    if link.shape is not None and link.shape.type == "ellipsoid":
        assert link.shape.radius is not None
        along = 2.0 * link.mass * link.shape.radius ** 2 / 5.0
    return link.inertia, along


def mjcf_from_model(model: RobotModel, *, contact: MjcfContact | None = None) -> str:
    """The model as MJCF text (module docstring): bodies, root joints, hinges about -y,
    inertials, contact spheres, the ground plane, motors for the joint actuators, and the
    contact and integration settings of ``contact`` (default :class:`MjcfContact`)."""
    c = contact or MjcfContact()
    if not (c.radius > 0 and c.friction > 0 and c.timestep > 0):
        raise ValueError(f"contact: radius, friction and timestep must be > 0, got {c!r}")
    names = [link.name for link in model.links] + [ct.name for ct in model.contacts]
    joints = [j.name for j in model.joints] + list(ROOT_JOINTS)
    for group, what in ((names, "bodies and geoms"), (joints, "joints")):
        dup = next((n for n in group if group.count(n) > 1), None)
        if dup is not None:
            raise ModelError(model.name, "links", dup, f"distinct names of {what} (MJCF names "
                             f"them in one namespace; {', '.join(ROOT_JOINTS)} are the root "
                             "joints)", problem=f"{dup!r} is used twice")
    root = ET.Element("mujoco", model=model.name)
    root.append(ET.Comment(
        f" written by gaitopt from the model {model.name!r}. Frames: gaitopt (x, y) = MuJoCo "
        "(x, z); the root hinge rooty turns about +y (gaitopt's base angle = -rooty), every "
        "other hinge about -y (angles, limits and torques are gaitopt's). Contact spheres are "
        "centred at gaitopt's contact points and the ground plane is one radius below "
        "gaitopt's ground (z = -radius), so a sphere touches it when its point is at height 0. "))
    # MuJoCo refuses a moving body whose mass or inertia is 0 (a point mass, a massless link
    # of a URDF import): the compiler raises those to BOUND_INERTIA (kg m^2) and BOUND_MASS
    # (kg), far below any link's and below the dynamics tests' 1e-9.
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true",
                  boundmass=_num(BOUND_MASS), boundinertia=_num(BOUND_INERTIA))
    gx, gy = model.gravity
    ET.SubElement(root, "option", timestep=_num(c.timestep), integrator=c.integrator,
                  gravity=f"{_num(gx)} 0.0 {_num(gy)}")
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", contype="0", conaffinity="0", condim="3",
                  friction=f"{_num(c.friction)} 0.005 0.0001", solref=_nums(c.solref),
                  solimp=_nums(c.solimp), rgba="0.45 0.55 0.7 1")
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", pos="0 -3 3", dir="0 1 -1", directional="true")
    ET.SubElement(world, "geom", name="ground", type="plane", size="0 0 0.05",
                  pos=f"0 0 {_num(-c.radius)}", contype="1", conaffinity="1",
                  rgba="0.8 0.8 0.75 1")
    bodies: dict[str, ET.Element] = {}
    for link in model.links:
        if link.parent is None:
            body = ET.SubElement(world, "body", name=link.name, pos="0 0 0")
            ET.SubElement(body, "camera", name="track", mode="trackcom", pos="0 -3 0.2",
                          xyaxes="1 0 0 0 0 1")
            for name, kind, axis in zip(ROOT_JOINTS, ("slide", "slide", "hinge"),
                                        ("1 0 0", "0 0 1", "0 1 0"), strict=True):
                ET.SubElement(body, "joint", name=name, type=kind, axis=axis, limited="false",
                              armature="0", damping="0")
        else:
            assert link.joint is not None
            parent = model.link(link.parent)
            body = ET.SubElement(bodies[link.parent], "body", name=link.name,
                                 pos=_xyz(parent.local_point(*link.joint.at)))
            ET.SubElement(body, "joint", name=link.joint.name, type="hinge", axis="0 -1 0",
                          range=_nums(link.joint.limits), limited="true", armature="0",
                          damping=_num(link.joint.damping))
        bodies[link.name] = body
        ixx, izz = _out_of_plane(link)
        ET.SubElement(body, "inertial", pos=_xyz(link.com_local), mass=_num(link.mass),
                      diaginertia=f"{_num(ixx)} {_num(link.inertia)} {_num(izz)}")
        ET.SubElement(body, "geom", name=f"{link.name}_visual", type="capsule", size="0.02",
                      fromto=f"0 0 0 {_xyz(link.local_point(link.length))}", mass="0")
    for ct in model.contacts:
        bodies[ct.link].append(ET.Comment(f" gaitopt contact point {ct.name!r} "))
        ET.SubElement(bodies[ct.link], "geom", name=ct.name, type="sphere",
                      size=_num(c.radius), pos=_xyz(model.link(ct.link).local_point(*ct.at)),
                      contype="0", conaffinity="1", mass="0", rgba="0.8 0.2 0.2 1")
    for link in model.links:  # a sole drawn between a link's contact points (feet)
        points = [model.link(ct.link).local_point(*ct.at) for ct in model.contacts
                  if ct.link == link.name]
        for p_from, p_to in zip(points, points[1:], strict=False):
            ET.SubElement(bodies[link.name], "geom", type="capsule", size="0.012",
                          fromto=f"{_xyz(p_from)} {_xyz(p_to)}", mass="0")
    actuators = ET.SubElement(root, "actuator")
    for a in model.actuators:
        if a.joint is not None:
            ET.SubElement(actuators, "motor", name=a.name, joint=a.joint, gear="1",
                          ctrllimited="true", ctrlrange=_nums(a.limits))
        else:
            actuators.append(ET.Comment(
                f" gaitopt actuator {a.name!r}: a torque between the ground and "
                f"{model.contact(a.contact or '').link!r} while {a.contact!r} is on the ground, "
                f"bounds {_nums(a.limits)} N m: not a joint; gaitopt simulate applies it as an "
                "external torque "))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"
