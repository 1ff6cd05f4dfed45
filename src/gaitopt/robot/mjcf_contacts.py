"""Contact points of the MJCF import: from ``--contact NAME=BODY:X,Z``, or inferred from the
foot geoms by :func:`gaitopt.robot.contact_inference.infer_contacts`.

The geoms of the bodies that make up a leaf link (a link no other link hangs from) become
planar shapes in that link's gaitopt frame (x, y in m, origin at its joint, parallel to the
world at ``qpos0``), from MuJoCo's ``geom_xpos`` and ``geom_xmat`` at ``qpos0`` (so
``geom_pos``, ``geom_quat`` and ``fromto`` as compiled) and ``geom_size``:

- a sphere, or a capsule or cylinder whose axis is the plane normal: a :class:`Circle`;
- a capsule whose axis lies in the plane: a :class:`Capsule` (ends ``c +- h a``, a its axis);
- a cylinder whose axis lies in the plane: a :class:`Rectangle` with half sizes ``(h, r)``;
- a box with one axis along the normal: a :class:`Rectangle` with the other two half sizes.

A capsule, cylinder or box tilted out of the plane is refused, naming the geom and the link,
as the URDF import does (``--contact`` avoids the geoms); meshes, ellipsoids and other types
are skipped with a note, and so are visual geoms (``contype`` and ``conaffinity`` both 0).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from gaitopt.robot.contact_inference import Capsule, Circle, Rectangle, Shape, infer_contacts
from gaitopt.robot.errors import ModelError
from gaitopt.robot.schema import model_from_dict
from gaitopt.robot.urdf import ContactSpec
from gaitopt.robot.urdf_plane import AXIS_TOL, IN_PLANE_ROWS, NORMAL, SNAP

#: A capsule's or cylinder's axis is its frame's z axis (MuJoCo's convention).
GEOM_AXIS = 2

if TYPE_CHECKING:
    from gaitopt.robot.mjcf_build import Builder, Link, Vec


def contact_points(builder: Builder, links: list[Link], link_of: dict[int, int],
                   specs: list[ContactSpec], name: str | None) -> list[tuple[str, int, Vec]]:
    """``(name, link index, gaitopt (x, y) relative to the link origin)`` per contact point:
    the ``specs`` when given (a point ``(X, Z)`` m in MuJoCo body BODY's frame), else those
    inferred from the leaf links' geoms (the module docstring)."""
    if not specs:
        return inferred(builder, links, link_of, name)
    m, d, mj = builder.m, builder.d, builder.mj
    out: list[tuple[str, int, Vec]] = []
    for spec in specs:
        if spec.name in {c[0] for c in out}:
            raise builder.fail(f"contact {spec.name!r}", spec.name, "a contact name not used "
                               "by another contact", problem="a duplicate contact name")
        b = mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, spec.link)
        if b not in link_of:
            names = ", ".join(builder.name("body", i) for i in link_of)
            raise builder.fail(f"contact {spec.name!r}", spec.link, f"the name of a body of the "
                               f"robot ({names})", problem=f"no body {spec.link!r}" if b < 0
                               else f"body {spec.link!r} is not part of the robot")
        local = np.zeros(3)
        local[builder.in_plane[0]], local[builder.in_plane[1]] = spec.point
        world = d.xpos[b] + d.xmat[b].reshape(3, 3) @ local
        k = link_of[b]
        out.append((spec.name, k, builder.xy(world - links[k].origin)))
    builder.notes.append(f"contacts: {', '.join(s.name for s in specs)} from --contact (the "
                         "geoms are not used)")
    return out


def inferred(builder: Builder, links: list[Link], link_of: dict[int, int], name: str | None
             ) -> list[tuple[str, int, Vec]]:
    """The contact points :func:`infer_contacts` finds on the leaf links' geoms."""
    m = builder.m
    parents = {link.parent for link in links}
    leaves = {b: k for b, k in link_of.items() if k not in parents}
    shapes: list[Shape] = []
    skipped: list[str] = []
    for g in range(m.ngeom):
        k = leaves.get(int(m.geom_bodyid[g]))
        if k is None or (m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0):
            continue
        shape = geom_shape(builder, g, links[k])
        if isinstance(shape, str):
            skipped.append(f"{builder.name('geom', g)} ({shape})")
        else:
            shapes.append(shape)
    model = model_from_dict(builder.to_dict(links, [], name), source=builder.label)
    found = infer_contacts(model, shapes, source=builder.label)
    if found.contacts:
        builder.notes.append(f"contacts: {', '.join(c.name for c in found.contacts)} (inferred "
                             "from the foot geoms at qpos0; --contact overrides):")
        builder.notes.extend(f"  {line}" for line in found.lines())
    else:
        builder.notes.append("contacts: none (no usable geom on a leaf link; give them with "
                             "--contact NAME=BODY:X,Z)")
    if skipped:
        builder.notes.append(f"  geoms skipped (not a sphere, capsule, cylinder or box): "
                             f"{', '.join(skipped)}")
    index = {link.name: k for k, link in enumerate(links)}
    return [(c.name, index[c.link], np.array(model.link(c.link).local_point(*c.at)))
            for c in found.contacts]


def tilted(builder: Builder, g: int, link: Link, which: str) -> ModelError:
    """The error of a foot geom that is neither in the plane nor normal to it."""
    return builder.fail(f"link {link.name!r} geom {builder.name('geom', g)!r}",
                        "tilted out of the plane", f"a foot geom whose axes lie in the plane "
                        f"or along its normal (+-{builder.axis}), or contacts given with "
                        "--contact", problem=f"{which} neither in the plane nor normal to it")


def geom_shape(builder: Builder, g: int, link: Link) -> Shape | str:
    """Geom ``g`` as a planar shape in ``link``'s gaitopt frame, or why it cannot be one."""
    m, d, mj = builder.m, builder.d, builder.mj
    kind = int(m.geom_type[g])
    size = m.geom_size[g]
    center = builder.xy(d.geom_xpos[g] - link.origin)
    c = (float(center[0]), float(center[1]))
    axes = builder.plane @ d.geom_xmat[g].reshape(3, 3)  # columns: the geom's axes, gaitopt
    axes = np.where(np.abs(axes) < SNAP, 0.0, axes)      # rounding dust of the quaternion
    # per geom axis (x, y, z of the geom frame): along the plane normal, or in the plane
    normal = [abs(abs(float(axes[NORMAL, i])) - 1.0) <= AXIS_TOL for i in range(3)]
    in_plane = [abs(float(axes[NORMAL, i])) <= AXIS_TOL for i in range(3)]
    geom = mj.mjtGeom
    if kind == int(geom.mjGEOM_SPHERE):
        return Circle(link.name, c, float(size[0]))
    if kind in (int(geom.mjGEOM_CAPSULE), int(geom.mjGEOM_CYLINDER)):
        r, h = float(size[0]), float(size[1])
        if normal[GEOM_AXIS]:
            return Circle(link.name, c, r)
        if not in_plane[GEOM_AXIS]:
            raise tilted(builder, g, link, "its axis")
        a = axes[IN_PLANE_ROWS, GEOM_AXIS]
        if kind == int(geom.mjGEOM_CAPSULE):
            ends = tuple((float(center[0] + s * h * a[0]), float(center[1] + s * h * a[1]))
                         for s in (-1.0, 1.0))
            return Capsule(link.name, (ends[0], ends[1]), r)
        return Rectangle(link.name, c, (h, r), math.atan2(float(a[1]), float(a[0])))
    if kind == int(geom.mjGEOM_BOX):
        if not any(normal):
            raise tilted(builder, g, link, "none of its axes")
        i, j = (n for n in range(3) if not normal[n])
        return Rectangle(link.name, c, (float(size[i]), float(size[j])),
                         math.atan2(float(axes[1, i]), float(axes[0, i])))
    return str(mj.mjtGeom(kind).name).removeprefix("mjGEOM_").lower()

