"""Contact points inferred from collision geometry (any importer: URDF, MJCF).

An importer that finds no contact points in its file describes the collision shapes of the
robot's links in the plane and calls :func:`infer_contacts`. The shapes (frozen dataclasses)
are planar, in metres, in the **gaitopt link frame** of ``link``: origin at the link's joint,
x forward and y up when the robot stands at the zero pose (every angle 0), where every gaitopt
link frame is parallel to the world (``docs/conventions.md``). So "lowest" is the smallest y in
the link frame, and "rear" and "front" the smallest and largest x. Importers convert their own
frames into this one; the contact points come back as the model's ``[along, across]``.

- :class:`Circle`: a sphere, or a cylinder whose axis is out of the plane.
- :class:`Capsule`: a capsule whose axis lies in the plane, from ``ends[0]`` to ``ends[1]``.
- :class:`Rectangle`: a box, or a cylinder whose axis lies in the plane; ``angle`` (rad, CCW)
  turns its first half-size axis from the link frame's x axis.

The rules (``docs/urdf.md``), applied to the shapes on **leaf links** (links no other link
hangs from; shapes on other links, such as a thigh's capsule, are not feet and are skipped):

- a circle (radius 0 too) gives one point, its lowest: ``(cx, cy - r)``;
- an elongated shape lying down (a capsule whose axis is within 45 degrees of horizontal, a
  rectangle whose bottom side is its longer side) gives a *heel* and a *toe*: the rear and
  front ends of its bottom edge (for a capsule, the axis moved down by the radius);
- standing up (a capsule within 45 degrees of vertical, a rectangle whose bottom side is its
  shorter one) it gives one point: the lowest point of the capsule, the middle of the
  rectangle's bottom side; a rectangle with a corner down (no side lowest) its lowest corner;
- several shapes on one leaf: those reaching within :data:`LEVEL_TOL` of the leaf's lowest
  point count; their points give a heel and a toe (the rearmost and the frontmost) if they
  are more than :data:`LEVEL_TOL` apart in x, else one point.

Names follow the built-in models: the leaves with contacts are numbered 1, 2, ... in the order
of the model's links (the first is leg 1, the stance leg at the start of a step); a leaf with
one point gets ``tip_k``, one with two ``heel_k`` and ``toe_k`` (in that order).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from gaitopt.robot.errors import ModelError
from gaitopt.robot.model import Contact, RobotModel
from gaitopt.robot.urdf_plane import SNAP, link_point

#: Two points less than this apart (m) in height are level; in x, the same point.
LEVEL_TOL = 1e-6

Point = tuple[float, float]


@dataclass(frozen=True)
class Circle:
    """A sphere, or a cylinder whose axis is out of the plane: ``center`` (x, y) in m in the
    gaitopt link frame of ``link``, ``radius`` >= 0 m."""

    link: str
    center: tuple[float, float]
    radius: float


@dataclass(frozen=True)
class Capsule:
    """A capsule whose axis lies in the plane: the segment between ``ends`` ((x, y), (x, y))
    in m in the gaitopt link frame of ``link``, swept by a disc of ``radius`` >= 0 m."""

    link: str
    ends: tuple[tuple[float, float], tuple[float, float]]
    radius: float


@dataclass(frozen=True)
class Rectangle:
    """A box, or a cylinder whose axis lies in the plane: ``center`` (x, y) in m in the gaitopt
    link frame of ``link``, ``half_size`` (>= 0 m) along its own two axes, the first turned by
    ``angle`` rad (CCW) from the link frame's x axis."""

    link: str
    center: tuple[float, float]
    half_size: tuple[float, float]
    angle: float


Shape = Circle | Capsule | Rectangle


@dataclass(frozen=True)
class InferredContacts:
    """The inferred contact points (in model order: leg 1 first) and, for people, what each
    came from (:meth:`lines`)."""

    contacts: tuple[Contact, ...]
    notes: tuple[str, ...]

    def lines(self) -> list[str]:
        """One line per leaf that gave contacts (names, points, the shape), and one for the
        shapes skipped on links that are not leaves; ``["no collision shape on a leaf
        link"]`` when nothing was inferred."""
        return list(self.notes)


def describe(shape: Shape) -> str:
    """A shape in a few words, e.g. ``sphere r=0.05 at (0, -0.5)`` (m, link frame)."""
    if isinstance(shape, Circle):
        return f"sphere r={shape.radius:g} at {_pt(shape.center)}"
    if isinstance(shape, Capsule):
        return (f"capsule r={shape.radius:g} from {_pt(shape.ends[0])} to "
                f"{_pt(shape.ends[1])}")
    return (f"box {2 * shape.half_size[0]:g} x {2 * shape.half_size[1]:g} at "
            f"{_pt(shape.center)} turned {shape.angle:g} rad")


def _pt(p: Sequence[float]) -> str:
    return f"({p[0]:g}, {p[1]:g})"


def _snap(x: float) -> float:
    return 0.0 if abs(x) < SNAP else x + 0.0


def shape_points(shape: Shape) -> tuple[Point, ...]:
    """The contact points of one shape (the rules in the module docstring), in the link frame
    (x, y) in m: one point, or ``(heel, toe)`` with ``heel[0] < toe[0]``."""
    if isinstance(shape, Circle):
        cx, cy = shape.center
        return ((cx, cy - shape.radius),)
    if isinstance(shape, Capsule):
        (x0, y0), (x1, y1) = shape.ends
        r = shape.radius
        dx, dy = x1 - x0, y1 - y0
        if abs(dx) <= abs(dy):  # standing up (or a sphere): the lower end's lowest point
            x, y = (x0, y0) if y0 <= y1 else (x1, y1)
            return ((x, y - r),)
        norm = math.hypot(dx, dy)
        nx, ny = dy / norm, -dx / norm  # a unit normal of the axis ...
        if ny > 0.0:
            nx, ny = -nx, -ny           # ... pointing down
        a = (_snap(x0 + r * nx), _snap(y0 + r * ny))
        b = (_snap(x1 + r * nx), _snap(y1 + r * ny))
        return (a, b) if a[0] < b[0] else (b, a)
    cx, cy = shape.center
    hx, hy = shape.half_size
    c, s = math.cos(shape.angle), math.sin(shape.angle)
    u, v = (c, s), (-s, c)  # the rectangle's axes in the link frame
    # the sides: (outward normal, half length along the side, the side's direction)
    sides = [((u[0], u[1]), hx, hy, v), ((-u[0], -u[1]), hx, hy, v),
             ((v[0], v[1]), hy, hx, u), ((-v[0], -v[1]), hy, hx, u)]
    sides.sort(key=lambda side: side[0][1])
    (n, depth, half, along), second = sides[0], sides[1]
    if second[0][1] - n[1] <= 1e-12:  # a corner down: the lowest of the four corners
        corners = [(cx + sx * hx * u[0] + sy * hy * v[0], cy + sx * hx * u[1] + sy * hy * v[1])
                   for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)]
        x, y = min(corners, key=lambda p: p[1])
        return ((_snap(x), _snap(y)),)
    mx, my = cx + depth * n[0], cy + depth * n[1]  # the middle of the bottom side
    if half < depth:  # standing up: the bottom side is the shorter one
        return ((_snap(mx), _snap(my)),)
    a = (_snap(mx - half * along[0]), _snap(my - half * along[1]))
    b = (_snap(mx + half * along[0]), _snap(my + half * along[1]))
    return (a, b) if a[0] < b[0] else (b, a)


def _check(shape: Shape, model: RobotModel, source: str) -> None:
    """A one-line ModelError naming the link and the shape for an unusable shape."""
    kind = type(shape).__name__.lower()
    where = f"link {shape.link!r} {kind}"
    names = [link.name for link in model.links]
    if shape.link not in names:
        raise ModelError(source, where, shape.link,
                         f"a collision shape on a link of the model ({', '.join(names)})",
                         problem=f"no link {shape.link!r}")
    if isinstance(shape, Circle):
        numbers, sizes = [*shape.center, shape.radius], [shape.radius]
    elif isinstance(shape, Capsule):
        numbers, sizes = [*shape.ends[0], *shape.ends[1], shape.radius], [shape.radius]
    else:
        numbers = [*shape.center, *shape.half_size, shape.angle]
        sizes = list(shape.half_size)
    if not all(isinstance(x, int | float) and math.isfinite(x) for x in numbers):
        raise ModelError(source, where, describe(shape),
                         "finite coordinates and sizes (m, rad)")
    if any(x < 0.0 for x in sizes):
        raise ModelError(source, where, describe(shape), "a radius and half sizes >= 0 (m)")


def infer_contacts(model: RobotModel, shapes: Sequence[Shape], *,
                   source: str = "<collision shapes>") -> InferredContacts:
    """Contact points from the collision ``shapes`` of ``model`` (the module docstring).

    Args:
        model: the imported model (its contacts are not looked at): its links, which of them
            are leaves, and their directions (to write points as ``[along, across]``).
        shapes: circles, capsules and rectangles in the gaitopt link frames (x, y), m.
        source: the file the shapes came from, for errors.

    Returns:
        The contacts ``tip_k`` or ``heel_k, toe_k`` per leaf with shapes, leaves in the
        model's link order, and the lines saying where each came from.

    Raises:
        ModelError: a shape on an unknown link, with a negative size or a non-finite number
            (one line naming the link and the shape).
    """
    for shape in shapes:
        _check(shape, model, source)
    parents = {link.parent for link in model.links}
    leaves = [link for link in model.links if link.name not in parents]
    contacts: list[Contact] = []
    notes: list[str] = []
    k = 0
    for leaf in leaves:
        mine = [s for s in shapes if s.link == leaf.name]
        if not mine:
            continue
        k += 1
        per_shape = [(s, shape_points(s)) for s in mine]
        lowest = min(p[1] for _, pts in per_shape for p in pts)
        used = [(s, pts) for s, pts in per_shape
                if min(p[1] for p in pts) <= lowest + LEVEL_TOL]
        points = [p for _, pts in used for p in pts]
        rear, front = min(points, key=lambda p: p[0]), max(points, key=lambda p: p[0])
        from_ = " and ".join(describe(s) for s, _ in used)
        if front[0] - rear[0] > LEVEL_TOL:
            named = [(f"heel_{k}", rear), (f"toe_{k}", front)]
            how = "the rear and front ends of the bottom of"
        else:
            named = [(f"tip_{k}", min(points, key=lambda p: p[1]))]
            how = "the lowest point of"
        for name, p in named:
            along, across = link_point(p, leaf.direction)
            contacts.append(Contact(name=name, link=leaf.name, at=(along, across)))
        said = ", ".join(f"{n} at {_pt(p)}" for n, p in named)
        notes.append(f"{said} m in link {leaf.name!r}: {how} its {from_}")
    skipped = sorted({s.link for s in shapes if s.link not in {leaf.name for leaf in leaves}})
    if skipped:
        notes.append(f"shapes on links that are not leaves are not feet: {', '.join(skipped)}")
    if not contacts:
        notes.insert(0, "no collision shape on a leaf link")
    return InferredContacts(tuple(contacts), tuple(notes))


__all__ = ["LEVEL_TOL", "Capsule", "Circle", "InferredContacts", "Rectangle", "Shape",
           "describe", "infer_contacts", "shape_points"]
