"""The body walk of the MJCF import (:mod:`gaitopt.robot.mjcf`): a compiled ``mujoco.MjModel``
-> links, joints, actuators, contacts and the coordinate map, with the notes the import prints.

All positions are read from MuJoCo's forward kinematics at ``qpos0`` (world frame, m) and
turned into gaitopt (x, y) by the rows of the plane matrix ``plane`` (gaitopt x, y, z as MuJoCo
vectors; :data:`gaitopt.robot.urdf_plane.PLANE`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gaitopt.robot.errors import ModelError
from gaitopt.robot.mjcf_contacts import contact_points
from gaitopt.robot.mjcf_result import UNLIMITED, CoordinateMap, MjcfImport
from gaitopt.robot.model import BASE_ANGLE, BASE_COORDINATES
from gaitopt.robot.schema import model_from_dict
from gaitopt.robot.urdf import ContactSpec
from gaitopt.robot.urdf_assumptions import declare_foot_symmetry, symmetry_note
from gaitopt.robot.urdf_plane import (
    AXIS_TOL,
    IN_PLANE_ROWS,
    NORMAL,
    SNAP,
    direction_and_length,
    link_point,
)

Vec = NDArray[np.float64]
#: Rows of a plane matrix: gaitopt x and y (the plane) and z (its normal), as MuJoCo vectors.
#: The number of base coordinates (x, y, angle) at the start of q.
N_BASE = len(BASE_COORDINATES)
#: For each common hinge axis, the MuJoCo axes of gaitopt x and y: the base slides' axes.
SLIDE_AXES = {"y": ("x", "z"), "x": ("y", "z")}


@dataclass
class Link:
    """A gaitopt link under construction: MuJoCo bodies welded together."""

    name: str
    parent: int
    origin: Vec                               # world (MuJoCo) position at qpos0, m
    joint: dict[str, Any] | None = None       # name, at (gaitopt x, y rel. parent), limits
    bodies: list[int] = field(default_factory=list)
    points: list[Vec] = field(default_factory=list)  # child joints, contacts (x, y rel.)


def merge_parts(parts: Sequence[tuple[float, Vec, float]]) -> tuple[float, Vec, float]:
    """Mass (kg), centre of mass (m) and inertia about it (kg m^2) of rigidly joined parts
    ``(m_k, c_k, I_k)`` in one plane: ``m = sum m_k``, ``c = sum m_k c_k / m``,
    ``I = sum (I_k + m_k |c_k - c|^2)`` (parallel-axis theorem)."""
    if len(parts) == 1:
        return parts[0]
    mass = sum(mk for mk, _, _ in parts)
    com = sum((mk * ck for mk, ck, _ in parts), np.zeros(2)) / mass
    return mass, com, sum(ik + mk * float(np.sum((ck - com) ** 2)) for mk, ck, ik in parts)


def _values(values: dict[str, float] | dict[str, str], unit: str) -> str:
    """``0.01 kg m^2 on a, b; 0.02 kg m^2 on c`` (names grouped by value, in order)."""
    groups: dict[float | str, list[str]] = {}
    for name, v in values.items():
        groups.setdefault(v, []).append(name)
    return "; ".join(f"{v if isinstance(v, str) else format(v, 'g')} {unit} on "
                     f"{', '.join(names)}" for v, names in groups.items())


class Builder:
    """One import: ``Builder(mujoco, model, label, plane, in_plane, axis).build(specs, name)``."""

    def __init__(self, mujoco: Any, m: Any, label: str, plane: Vec,
                 in_plane: tuple[int, int], axis: str) -> None:
        self.mj, self.m, self.label, self.plane, self.in_plane, self.axis = (
            mujoco, m, label, plane, in_plane, axis)
        self.d = mujoco.MjData(m)
        self.d.qpos[:] = m.qpos0
        mujoco.mj_kinematics(m, self.d)
        self.notes: list[str] = []

    # -- helpers -----------------------------------------------------------------------------
    def fail(self, path: str, value: Any, allowed: str, problem: str | None = None
             ) -> ModelError:
        return ModelError(self.label, path, value, allowed, problem=problem)

    def name(self, kind: str, i: int) -> str:
        """The MuJoCo name of object ``i`` of ``kind`` (body, joint, actuator, geom), or
        ``KIND<i>`` for an unnamed one."""
        return self.given_name(kind, i) or f"{kind}{i}"

    def given_name(self, kind: str, i: int) -> str | None:
        """The MuJoCo name of object ``i`` of ``kind``, None if it has none."""
        obj = getattr(self.mj.mjtObj, f"mjOBJ_{kind.upper()}")
        return self.mj.mj_id2name(self.m, obj, i) or None

    def xy(self, v: Vec) -> Vec:
        """gaitopt (x, y) of a MuJoCo world vector; rounding dust (|x| < SNAP m) becomes 0."""
        g = self.plane[IN_PLANE_ROWS] @ v + 0.0
        return np.where(np.abs(g) < SNAP, 0.0, g)

    def joint_axis(self, j: int) -> Vec:
        """The joint's axis as gaitopt (x, y, z) at qpos0."""
        return self.plane @ self.d.xaxis[j]

    def about_normal(self, j: int) -> float:
        """+1 for a hinge about gaitopt +z (MuJoCo -y), -1 about -z; else a ModelError."""
        g = self.joint_axis(j)
        if abs(abs(g[NORMAL]) - 1.0) > AXIS_TOL:
            raise self.fail(f"joint {self.name('joint', j)!r} axis",
                            " ".join(f"{x:.6g}" for x in self.m.jnt_axis[j]),
                            f"a hinge axis along +-{self.axis} in the world at qpos0 (the "
                            "common hinge axis; the robot is planar)")
        return 1.0 if g[NORMAL] > 0 else -1.0

    def kind(self, j: int) -> str:
        """``slide``, ``hinge``, ``ball`` or ``free``: joint ``j``'s type."""
        return str(self.mj.mjtJoint(int(self.m.jnt_type[j])).name).removeprefix("mjJNT_").lower()

    def joints_of(self, b: int) -> list[int]:
        start = int(self.m.body_jntadr[b])
        return list(range(start, start + int(self.m.body_jntnum[b])))

    def ancestors(self, b: int) -> list[int]:
        out = []
        while b != 0:
            b = int(self.m.body_parentid[b])
            out.append(b)
        return out

    # -- the floating base -------------------------------------------------------------------
    def base(self) -> tuple[int, list[tuple[int, int, float, float]]]:
        """The base body and its coordinates ``(joint, gaitopt index, sign, offset)``."""
        m, mj = self.m, self.mj
        roots = [b for b in range(1, m.nbody) if m.body_jntnum[b] > 0
                 and all(m.body_jntnum[a] == 0 for a in self.ancestors(b))]
        along = SLIDE_AXES[self.axis]
        allowed = (f"one body with two slide joints along {along[0]} and {along[1]} and then a "
                   f"hinge about {self.axis} (the floating base), its descendants the robot")
        if len(roots) != 1:
            names = [self.name("body", b) for b in roots]
            raise self.fail("worldbody", names, allowed, problem=f"{len(roots)} bodies with "
                            f"joints below the world ({', '.join(names) or 'none'})")
        b = roots[0]
        joints = self.joints_of(b)
        kinds = [int(m.jnt_type[j]) for j in joints]
        slide, hinge = int(mj.mjtJoint.mjJNT_SLIDE), int(mj.mjtJoint.mjJNT_HINGE)
        text = ", ".join(f"{self.name('joint', j)} ({self.kind(j)})" for j in joints)
        where = f"body {self.name('body', b)!r} joints"
        if kinds != [slide, slide, hinge]:
            raise self.fail(where, text, allowed, problem=f"got {text}")
        coords: list[tuple[int, int, float, float]] = []
        *slides, hinge_joint = joints
        origin = self.xy(self.d.xanchor[hinge_joint])
        for j in slides:
            g = self.joint_axis(j)
            k = int(np.argmax(np.abs(g)))  # gaitopt x (0) or y (1), not the normal
            if k == NORMAL or abs(abs(g[k]) - 1.0) > AXIS_TOL:
                raise self.fail(where, text, allowed, problem=f"slide "
                                f"{self.name('joint', j)!r} is not along {along[0]} or {along[1]}")
            coords.append((j, k, 1.0 if g[k] > 0 else -1.0, float(origin[k])))
        if sorted(c[1] for c in coords) != [0, 1]:
            raise self.fail(where, text, allowed, problem="both slides along one axis")
        coords.append((hinge_joint, BASE_ANGLE, self.about_normal(hinge_joint), 0.0))
        return b, sorted(coords, key=lambda c: c[1])

    def base_note(self, base: int, coords: list[tuple[int, int, float, float]]) -> str:
        """``floating base: body 'torso'; the MuJoCo joints ... became its coordinates ...``."""
        joints = ", ".join(f"{self.name('joint', j)} ({self.kind(j)})"
                           for j in self.joints_of(base))
        names = ("x", "y", self.name("body", base))
        parts = [f"{names[k]} = {'' if sign > 0 else '-'}{self.name('joint', j)}"
                 for j, k, sign, _ in coords]
        (_, _, _, x), (_, _, _, y), (hinge_joint, _, _, _) = coords
        return (f"floating base: body {self.name('body', base)!r}; the MuJoCo joints {joints} "
                f"became its coordinates {', '.join(parts)} (its origin: "
                f"{self.name('joint', hinge_joint)}'s anchor, at ({x:g}, {y:g}) m at qpos0)")

    def joints_note(self, coords: list[tuple[int, int, float, float]]) -> str:
        """``joints: 6 hinges; about -y (angle = qpos - qpos0): a, b; about +y ...``."""
        groups: dict[float, list[str]] = {1.0: [], -1.0: []}
        for j, _, sign, _ in coords:
            groups[sign].append(self.name("joint", j))
        parts = [f"about -{self.axis} (angle = qpos - qpos0; limits and torques as MuJoCo's): "
                 f"{', '.join(groups[1.0])}"] if groups[1.0] else []
        if groups[-1.0]:
            parts.append(f"about +{self.axis} (angles, limits and torques change sign): "
                         f"{', '.join(groups[-1.0])}")
        return f"joints: {len(coords)} hinges; " + "; ".join(parts)

    # -- the model ---------------------------------------------------------------------------
    def build(self, specs: list[ContactSpec], name: str | None) -> MjcfImport:
        m, mj = self.m, self.mj
        if m.neq > 0:
            raise self.fail("equality", self.name("equality", 0), "a tree without equality "
                            "constraints (gaitopt models are open trees)",
                            problem=f"{m.neq} equality constraint(s)")
        base, base_coords = self.base()
        self.notes.append(self.base_note(base, base_coords))
        root_hinge = base_coords[BASE_ANGLE][0]
        links = [Link(self.name("body", base), -1, self.d.xanchor[root_hinge].copy(),
                      bodies=[base])]
        link_of = {base: 0}
        coords = list(base_coords)
        hinge = int(mj.mjtJoint.mjJNT_HINGE)
        for b in range(base + 1, m.nbody):
            parent = int(m.body_parentid[b])
            if parent not in link_of:
                continue  # a static body fixed to the world
            k = link_of[parent]
            joints = self.joints_of(b)
            if not joints:
                link_of[b] = k
                links[k].bodies.append(b)
                continue
            j = joints[0]
            if len(joints) > 1 or m.jnt_type[j] != hinge:
                kinds = ", ".join(f"{self.name('joint', i)} ({self.kind(i)})" for i in joints)
                raise self.fail(f"body {self.name('body', b)!r} joints", kinds,
                                f"one hinge about {self.axis} per body below the floating "
                                "base (or none: welded to the parent)", problem=f"got {kinds}")
            sign = self.about_normal(j)
            q0 = float(m.qpos0[m.jnt_qposadr[j]])
            lo, hi = (sorted(sign * (float(r) - q0) + 0.0 for r in m.jnt_range[j])
                      if m.jnt_limited[j] else UNLIMITED)
            origin = self.d.xanchor[j].copy()
            at = self.xy(origin - links[k].origin)
            links[k].points.append(at)
            links.append(Link(self.name("body", b), k, origin, bodies=[b], joint={
                "name": self.name("joint", j), "at": at,
                "limits": [x if math.isfinite(x) else None for x in (lo, hi)]}))  # null: none
            link_of[b] = len(links) - 1
            coords.append((j, len(coords), sign, 0.0))
        self.notes.append(self.joints_note(coords[N_BASE:]))
        static = [self.name("body", b) for b in range(1, m.nbody)
                  if b not in link_of and b not in self.ancestors(base)]
        if static:
            self.notes.append(f"static bodies (fixed to the world, not the robot): "
                              f"{', '.join(static)}")
        cmap = CoordinateMap(
            names=tuple(self.name("joint", j) for j, _, _, _ in coords),
            qpos_index=tuple(int(m.jnt_qposadr[j]) for j, _, _, _ in coords),
            dof_index=tuple(int(m.jnt_dofadr[j]) for j, _, _, _ in coords),
            sign=tuple(s for _, _, s, _ in coords), offset=tuple(o for _, _, _, o in coords),
            qpos0=tuple(float(x) for x in m.qpos0))
        if len(coords) != m.nv:
            raise self.fail("", m.nv, f"{len(coords)} degrees of freedom (those of the robot)",
                            problem=f"{m.nv - len(coords)} degrees of freedom outside it")
        contacts = contact_points(self, links, link_of, specs, name)
        data = self.to_dict(links, contacts, name)
        data["actuators"] = self.actuators(links, cmap)
        data["gravity"] = self.gravity()
        if not specs:  # heel_1, toe_1, heel_2, toe_2 inferred: the feet's symmetry
            declare_foot_symmetry(data, source=self.label)
        model = model_from_dict(data, source=self.label)
        armature = tuple(float(m.dof_armature[d]) for d in cmap.dof_index)
        self.dropped(cmap)
        self.notes.append(symmetry_note(model, by_import="symmetry" in data))
        return MjcfImport(model, cmap, armature, tuple(self.notes))

    def link_parts(self, link: Link) -> tuple[float, Vec, float]:
        """Mass, centre of mass (gaitopt x, y relative to the link origin) and inertia about
        the normal n through it: ``n^T ximat diag(body_inertia) ximat^T n`` per body, merged."""
        n = self.plane[NORMAL]
        parts = []
        for b in link.bodies:
            mass = float(self.m.body_mass[b])
            if mass > 0.0:
                axis = self.d.ximat[b].reshape(3, 3).T @ n  # n in the body's inertia frame
                inertia = float(np.sum(self.m.body_inertia[b] * axis * axis))
                parts.append((mass, self.xy(self.d.xipos[b] - link.origin), inertia))
        if not parts:  # massless: the schema checks that the mass matrix stays invertible
            return 0.0, np.zeros(2), 0.0
        return merge_parts(parts)

    def to_dict(self, links: list[Link], contacts: list[tuple[str, int, Vec]],
                name: str | None) -> dict[str, Any]:
        for _, k, p in contacts:
            links[k].points.append(p)
        out: list[dict[str, Any]] = []
        for i, link in enumerate(links):
            mass, com, inertia = self.link_parts(link)
            direction, length = direction_and_length(link.points, com, base=i == 0)
            entry: dict[str, Any] = {"name": link.name,
                                     "parent": None if link.parent < 0 else links[link.parent].name}
            if link.joint is not None:
                entry["joint"] = {**link.joint, "at": link_point(
                    link.joint["at"], out[link.parent]["direction"])}
            entry.update({"direction": direction, "length": length, "mass": mass,
                          "com": link_point(com, direction), "inertia": inertia})
            out.append(entry)
        return {"name": name or self.m.names[:self.m.names.find(b"\0")].decode() or "robot",
                "links": out,
                "contacts": [{"name": c, "link": links[k].name,
                              "at": link_point(p, out[k]["direction"])} for c, k, p in contacts]}

    # -- actuators, gravity, what is dropped -------------------------------------------------
    def actuators(self, links: list[Link], cmap: CoordinateMap) -> list[dict[str, Any]]:
        """One gaitopt actuator per MuJoCo motor on a hinge, in MuJoCo's order: torque bounds
        ``sign * gear * [lo, hi]`` with [lo, hi] = ``gainprm[0] * ctrlrange`` (if
        ``ctrllimited``) intersected with ``forcerange`` (if ``forcelimited``)."""
        m, mj = self.m, self.mj
        coord_of = {cmap.dof_index[i]: i for i in range(N_BASE, len(cmap.sign))}
        out: list[dict[str, Any]] = []
        shown: dict[str, str] = {}
        for a in range(m.nu):
            name = self.name("actuator", a)
            j = int(m.actuator_trnid[a, 0])
            where = f"actuator {name!r}"
            if int(m.actuator_trntype[a]) not in (int(mj.mjtTrn.mjTRN_JOINT),
                                                  int(mj.mjtTrn.mjTRN_JOINTINPARENT)):
                raise self.fail(where, "a tendon, site or body transmission",
                                "a motor on a joint")
            dof = int(m.jnt_dofadr[j])
            if dof not in coord_of:
                raise self.fail(where, self.name("joint", j), "a motor on a hinge below the "
                                "floating base (gaitopt's base is unactuated)")
            if (int(m.actuator_gaintype[a]) != int(mj.mjtGain.mjGAIN_FIXED)
                    or int(m.actuator_biastype[a]) != int(mj.mjtBias.mjBIAS_NONE)
                    or int(m.actuator_dyntype[a]) != int(mj.mjtDyn.mjDYN_NONE)):
                raise self.fail(where, "a servo or an actuator with dynamics", "a motor (fixed "
                                "gain, no bias, no activation dynamics): gaitopt controls are "
                                "torques")
            lo, hi = -math.inf, math.inf
            if m.actuator_ctrllimited[a]:
                lo, hi = sorted(float(m.actuator_gainprm[a, 0]) * m.actuator_ctrlrange[a])
            if m.actuator_forcelimited[a]:
                lo, hi = max(lo, float(m.actuator_forcerange[a, 0])), min(
                    hi, float(m.actuator_forcerange[a, 1]))
            if not (math.isfinite(lo) and math.isfinite(hi)):
                raise self.fail(where, "no ctrlrange or forcerange", "a motor with ctrllimited "
                                "or forcelimited (gaitopt torque bounds are finite)")
            i = coord_of[dof]
            scale = cmap.sign[i] * float(m.actuator_gear[a, 0])
            bounds = sorted((scale * lo + 0.0, scale * hi + 0.0))
            out.append({"name": self.given_name("actuator", a) or cmap.names[i],
                        "joint": cmap.names[i], "limits": bounds})
            shown[out[-1]["name"]] = f"[{bounds[0]:g}, {bounds[1]:g}]"
        self.notes.append(f"actuators: {_values(shown, 'N m') or 'none'} (gear x ctrlrange of "
                          "MuJoCo's motors, in MuJoCo's order)")
        return out

    def gravity(self) -> list[float]:
        """gaitopt gravity (m/s^2): ``opt.gravity`` in the plane (0 when disabled); its
        component along the normal does no work on a planar robot and is dropped."""
        g = np.array(self.m.opt.gravity, dtype=float)
        if int(self.m.opt.disableflags) & int(self.mj.mjtDisableBit.mjDSBL_GRAVITY):
            g = np.zeros(3)
        out = self.xy(g)
        if abs(float(self.plane[NORMAL] @ g)) > 0.0:
            self.notes.append(f"gravity: its component {float(self.plane[NORMAL] @ g):g} m/s^2 "
                              "normal to the plane is dropped (no work in the plane)")
        return [float(out[0]), float(out[1])]

    def dropped(self, cmap: CoordinateMap) -> None:
        """Notes on what gaitopt models have no place for: armature, damping, friction loss,
        stiffness (per joint, grouped by value)."""
        m = self.m
        fields = (("armature", m.dof_armature, "kg m^2",
                   "no rotor inertia in gaitopt models; MuJoCo adds it to the mass matrix's "
                   "diagonal"),
                  ("damping", m.dof_damping, "N m s/rad", "no joint friction in gaitopt"),
                  ("frictionloss", m.dof_frictionloss, "N m", "no joint friction in gaitopt"),
                  ("stiffness", m.jnt_stiffness[m.dof_jntid], "N m/rad",
                   "no joint springs in gaitopt"))
        for label, values, unit, why in fields:
            found = {cmap.names[i]: float(values[d]) for i, d in enumerate(cmap.dof_index)
                     if values[d] != 0.0}
            if found:
                self.notes.append(f"{label}: dropped ({why}): {_values(found, unit)}")
