"""URDF ``<collision>`` geometry as planar shapes for contact inference.

A collision frame ``(R, p)`` given in a URDF link frame is re-expressed in the world-parallel
frame of the link's gaitopt link (``docs/urdf.md``), then projected into the sagittal plane
(``gaitopt (x, y, z) = PLANE @ URDF``, :mod:`gaitopt.robot.urdf_plane`):

- a sphere is a :class:`~gaitopt.robot.contact_inference.Circle`;
- a cylinder or capsule (axis along its frame's z) whose axis is normal to the plane is a
  circle; with the axis in the plane a capsule is a ``Capsule``, a cylinder a ``Rectangle``
  (half sizes: half its length along the axis, its radius across);
- a box (sizes along its frame's x, y, z) with one axis normal to the plane is a
  ``Rectangle`` of its two other sizes;
- a mesh gives nothing (its shape is not read).

Any other orientation (a tilted cylinder, a box turned out of the plane) is refused in one
line naming the link and the shape.
"""

from __future__ import annotations

import math

import numpy as np

from gaitopt.robot.contact_inference import Capsule, Circle, Rectangle, Shape
from gaitopt.robot.errors import ModelError
from gaitopt.robot.urdf_plane import AXIS_TOL, SNAP
from gaitopt.robot.urdf_xml import UCollision


def _snap(x: float) -> float:
    return 0.0 if abs(x) < SNAP else float(x) + 0.0


def planar_shape(c: UCollision, *, link: str, urdf_link: str, rot: np.ndarray,
                 pos: np.ndarray, plane: np.ndarray, source: str) -> Shape | None:
    """The shape of collision ``c`` of URDF link ``urdf_link`` in the frame of gaitopt link
    ``link`` (module docstring), or None for a mesh.

    Args:
        rot, pos: the URDF link's axes (3, 3) and origin (3,), m, in the gaitopt link's
            world-parallel frame, in URDF coordinates.
        plane: rows gaitopt x, y, z as URDF vectors (3, 3).
    """
    if c.kind == "mesh":
        return None
    frame = rot @ c.rot
    g = plane @ frame            # the collision frame's axes (columns) in gaitopt x, y, z
    cx, cy = (plane @ (pos + rot @ c.pos))[:2]
    center = (_snap(cx), _snap(cy))
    if c.kind == "sphere":
        return Circle(link, center, c.radius)
    where = f"link {urdf_link!r} collision {c.kind}"
    if c.kind in ("cylinder", "capsule"):
        axis = g[:, 2]
        if abs(abs(axis[2]) - 1.0) <= AXIS_TOL:
            return Circle(link, center, c.radius)
        if abs(axis[2]) <= AXIS_TOL:
            ux, uy = _snap(axis[0]), _snap(axis[1])
            if c.kind == "capsule":
                h = c.length / 2.0
                ends = ((_snap(cx - h * ux), _snap(cy - h * uy)),
                        (_snap(cx + h * ux), _snap(cy + h * uy)))
                return Capsule(link, ends, c.radius)
            return Rectangle(link, center, (c.length / 2.0, c.radius), math.atan2(uy, ux))
    else:  # box
        normal = [k for k in range(3) if abs(abs(g[2, k]) - 1.0) <= AXIS_TOL]
        if normal:
            first, second = (k for k in range(3) if k != normal[0])
            angle = math.atan2(_snap(g[1, first]), _snap(g[0, first]))
            return Rectangle(link, center, (c.size[first] / 2.0, c.size[second] / 2.0), angle)
    raise ModelError(source, where, " ".join(f"{x:.6g}" for x in frame[:, 2]),
                     "a collision shape turned only about the common joint axis (a cylinder "
                     "or capsule axis in the sagittal plane or normal to it, a box with a "
                     "face in the plane); or give the contacts with --contact",
                     problem="a shape tilted out of the sagittal plane")


__all__ = ["planar_shape"]
