"""Planar spatial algebra (Featherstone, *Rigid Body Dynamics Algorithms*, planar case).

Vectors are 3-tuples of scalars (floats or CasADi symbols, see :mod:`.backend`):

* a motion vector ``m = (omega, vx, vy)``: angular velocity about z (rad/s) and the linear
  velocity (m/s) of the body-fixed point at the frame origin, in the frame's coordinates;
* a force vector ``f = (n, fx, fy)``: moment about the frame origin (N m) and force (N).

A :class:`Transform` ``X`` from frame A to frame B (B's origin at ``r`` in A coordinates, B
rotated by ``theta`` from A, ``c = cos theta``, ``s = sin theta``) acts on motion vectors as
Featherstone's ``plnr(theta, r)``::

        [ 1               0   0 ]
    X = [ s rx - c ry     c   s ]
        [ c rx + s ry    -s   c ]

and on force vectors as ``X* = X^{-T}``; ``X^T`` maps forces from B back to A. Rigid-body
inertias are :class:`RigidInertia` ``(mass, hx, hy, inertia_origin)`` with ``h = m c`` the first
mass moment and ``inertia_origin = I_com + m |c|^2`` about the frame origin::

        [ Io  -hy  hx ]
    I = [ -hy   m   0 ]
        [ hx    0   m ]

Articulated-body inertias are general symmetric 3x3 matrices (tuples of rows).
"""

from __future__ import annotations

from typing import NamedTuple

from gaitopt.dynamics.backend import Scalar

Vec3 = tuple[Scalar, Scalar, Scalar]
Mat3 = tuple[Vec3, Vec3, Vec3]

ZERO3: Vec3 = (0.0, 0.0, 0.0)
ZERO_MAT3: Mat3 = (ZERO3, ZERO3, ZERO3)


class Transform(NamedTuple):
    """Planar Plücker transform from frame A to frame B (see the module docstring).

    ``identity`` marks the identity transform so the algorithms can skip it.
    """

    c: Scalar
    s: Scalar
    rx: Scalar
    ry: Scalar
    identity: bool = False


IDENTITY = Transform(1.0, 0.0, 0.0, 0.0, True)


def transform(c: Scalar, s: Scalar, rx: Scalar, ry: Scalar) -> Transform:
    """The transform to a frame at ``(rx, ry)`` rotated by the angle with cos ``c``, sin ``s``."""
    return Transform(c, s, rx, ry, False)


def motion_to_child(x: Transform, m: Vec3) -> Vec3:
    """``X m``: a motion vector in A coordinates expressed in B coordinates."""
    if x.identity:
        return m
    w, vx, vy = m
    # Velocity of the point at B's origin, in A coordinates, then rotated into B.
    px = vx - w * x.ry
    py = vy + w * x.rx
    return (w, x.c * px + x.s * py, -x.s * px + x.c * py)


def motion_to_parent(x: Transform, m: Vec3) -> Vec3:
    """``X^{-1} m``: a motion vector in B coordinates expressed in A coordinates."""
    if x.identity:
        return m
    w, vx, vy = m
    ax = x.c * vx - x.s * vy
    ay = x.s * vx + x.c * vy
    return (w, ax + w * x.ry, ay - w * x.rx)


def force_to_parent(x: Transform, f: Vec3) -> Vec3:
    """``X^T f``: a force vector in B coordinates expressed in A coordinates."""
    if x.identity:
        return f
    n, fx, fy = f
    ax = x.c * fx - x.s * fy
    ay = x.s * fx + x.c * fy
    return (n + x.rx * ay - x.ry * ax, ax, ay)


def cross_motion(v: Vec3, m: Vec3) -> Vec3:
    """``v x m`` (Featherstone's ``crm(v) m``) for motion vectors."""
    w, vx, vy = v
    mw, mx, my = m
    return (0.0, vy * mw - w * my, w * mx - vx * mw)


def cross_force(v: Vec3, f: Vec3) -> Vec3:
    """``v x* f`` (Featherstone's ``crf(v) f``) for a force vector."""
    w, vx, vy = v
    _n, fx, fy = f
    return (vx * fy - vy * fx, -w * fy, w * fx)


def add3(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub3(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale3(k: Scalar, a: Vec3) -> Vec3:
    return (k * a[0], k * a[1], k * a[2])


def dot3(a: Vec3, b: Vec3) -> Scalar:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def unit3(axis: int) -> Vec3:
    """The unit motion vector along coordinate ``axis`` (0: rotation, 1: x, 2: y)."""
    return (1.0 if axis == 0 else 0.0, 1.0 if axis == 1 else 0.0, 1.0 if axis == 2 else 0.0)


class RigidInertia(NamedTuple):
    """Planar rigid-body inertia about a frame origin: mass (kg), first moment ``h = m c``
    (kg m) and rotational inertia about the origin ``Io = I_com + m |c|^2`` (kg m^2)."""

    mass: Scalar
    hx: Scalar
    hy: Scalar
    inertia_origin: Scalar


ZERO_INERTIA = RigidInertia(0.0, 0.0, 0.0, 0.0)


def rigid_inertia(mass: float, com: tuple[float, float], inertia_com: float) -> RigidInertia:
    """The inertia of a body with ``mass``, centre of mass ``com`` (frame coordinates) and
    inertia ``inertia_com`` about the centre of mass."""
    cx, cy = com
    return RigidInertia(mass, mass * cx, mass * cy, inertia_com + mass * (cx * cx + cy * cy))


def inertia_times(inertia: RigidInertia, v: Vec3) -> Vec3:
    """``I v``: the momentum (moment about the origin, linear momentum) of the body."""
    m, hx, hy, io = inertia
    w, vx, vy = v
    return (io * w - hy * vx + hx * vy, m * vx - hy * w, m * vy + hx * w)


def inertia_matrix(inertia: RigidInertia) -> Mat3:
    m, hx, hy, io = inertia
    return ((io, -hy, hx), (-hy, m, 0.0), (hx, 0.0, m))


def add_inertia(a: RigidInertia, b: RigidInertia) -> RigidInertia:
    return RigidInertia(a.mass + b.mass, a.hx + b.hx, a.hy + b.hy,
                        a.inertia_origin + b.inertia_origin)


def inertia_to_parent(x: Transform, inertia: RigidInertia) -> RigidInertia:
    """``X^T I X``: a rigid-body inertia in B coordinates expressed in A coordinates."""
    if x.identity:
        return inertia
    m, hx, hy, io = inertia
    # h_A = m r + R h ; Io_A = Io + 2 r . (R h) + m |r|^2
    rhx = x.c * hx - x.s * hy
    rhy = x.s * hx + x.c * hy
    return RigidInertia(m, m * x.rx + rhx, m * x.ry + rhy,
                        io + 2.0 * (x.rx * rhx + x.ry * rhy)
                        + m * (x.rx * x.rx + x.ry * x.ry))


def mat3_times(a: Mat3, v: Vec3) -> Vec3:
    return (dot3(a[0], v), dot3(a[1], v), dot3(a[2], v))


def add_mat3(a: Mat3, b: Mat3) -> Mat3:
    return (add3(a[0], b[0]), add3(a[1], b[1]), add3(a[2], b[2]))


def mat3_to_parent(x: Transform, a: Mat3) -> Mat3:
    """``X^T A X`` for a symmetric 3x3 inertia-like matrix ``A`` in B coordinates."""
    if x.identity:
        return a
    # Columns of A X, then X^T applied to each column.
    cols = [force_to_parent(x, mat3_times(a, motion_to_child(x, unit3(j)))) for j in range(3)]
    rows = tuple((cols[0][i], cols[1][i], cols[2][i]) for i in range(3))
    # Symmetrize exactly.
    return ((rows[0][0], rows[0][1], rows[0][2]),
            (rows[0][1], rows[1][1], rows[1][2]),
            (rows[0][2], rows[1][2], rows[2][2]))
