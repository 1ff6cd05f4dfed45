"""Gaitopt links under construction from URDF links (merged by fixed joints), and their
model-file data: masses, centres of mass and inertias combined by the parallel-axis theorem
(a massless link keeps mass 0, a point mass inertia 0: the schema's mass-matrix check
decides), directions and lengths by the documented rule (``docs/urdf.md``), joint limits with
``null`` for no bound, contact points as ``[along, across]``.

Points are gaitopt (x, y) in m in a body's frame, which is parallel to the world at the
standing pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gaitopt.robot.inertia import INERTIA_RTOL, shape_inertia
from gaitopt.robot.model import Shape
from gaitopt.robot.urdf_plane import direction_and_length, link_point
from gaitopt.robot.urdf_xml import Extension


@dataclass
class Body:
    """A gaitopt link under construction: URDF links merged by fixed joints.

    ``parent`` is the index of the parent body (-1 for the base); ``joint`` the model-file
    joint (``at``: (x, y) in m in the parent's frame, ``limits`` in rad, +-inf for none);
    ``effort`` the URDF effort (N m, 0 if none); ``parts`` the merged URDF links' masses (kg),
    centres of mass ((2,), m) and inertias about them (kg m^2); ``points`` the child joints
    and contact points ((2,), m)."""

    name: str
    parent: int
    joint: dict[str, Any] | None
    effort: float = 0.0
    parts: list[tuple[float, np.ndarray, float]] = field(default_factory=list)  # m, com, I
    points: list[np.ndarray] = field(default_factory=list)  # joints and contacts (plane)


def standing(bodies: list[Body]) -> tuple[float, float]:
    """The total mass (kg) and the depth (m) of the lowest point (joints, contacts, centres
    of mass) below the base origin at the standing pose (every frame world-parallel)."""
    origin = [np.zeros(2) for _ in bodies]
    depth = 0.0
    for k, b in enumerate(bodies):  # parents come before their children
        if b.joint is not None:
            origin[k] = origin[b.parent] + b.joint["at"]
        for p in [*b.points, *(c for _, c, _ in b.parts)]:
            depth = max(depth, -float(origin[k][1] + p[1]))
    return sum(m for b in bodies for m, _, _ in b.parts), depth


def model_data(bodies: list[Body], contacts: list[tuple[str, int, np.ndarray]], name: str,
               ext: Extension) -> dict[str, Any]:
    """The model-file data (name, links, contacts, gravity, description; no actuators and no
    symmetry) of ``bodies`` (parents first) with ``contacts`` (name, body index, point (x, y)
    in m in the body's frame), applying the direction-and-length rule and what ``ext`` (the
    ``<gaitopt>`` element) says."""
    links: list[dict[str, Any]] = []
    for i, b in enumerate(bodies):
        mass = sum(m for m, _, _ in b.parts)  # 0 if massless: the schema's check decides
        com = (np.zeros(2) if not b.parts else b.parts[0][1] if len(b.parts) == 1 else
               sum((m * c for m, c, _ in b.parts), np.zeros(2)) / mass)
        inertia = sum((i_ + m * float(np.sum((c - com) ** 2)) for m, c, i_ in b.parts), 0.0)
        direction, length = ext.links.get(b.name) or direction_and_length(
            b.points, com, base=i == 0)
        entry: dict[str, Any] = {"name": b.name,
                                 "parent": None if b.parent < 0 else bodies[b.parent].name}
        if b.joint is not None:
            # the joint's position is a point on the parent (listed before its children);
            # an infinite limit is no bound (null)
            entry["joint"] = {**b.joint, "at": link_point(b.joint["at"],
                                                      links[b.parent]["direction"]),
                              "limits": [x if math.isfinite(x) else None
                                         for x in b.joint["limits"]]}
        entry.update({"direction": direction, "length": length, "mass": mass,
                      "com": link_point(com, direction), "inertia": inertia})
        shape = ext.shapes.get(b.name)
        if shape is not None:
            s = Shape(type=shape["type"], radius=shape.get("radius"))
            expected = shape_inertia(s, mass, length)
            if abs(expected - inertia) <= INERTIA_RTOL * expected:
                entry["shape"] = shape
        links.append(entry)
    directions = {b.name: links[i]["direction"] for i, b in enumerate(bodies)}
    data: dict[str, Any] = {
        "name": name, "links": links,
        "contacts": [{"name": c, "link": bodies[k].name, "at": link_point(p, directions[
            bodies[k].name])} for c, k, p in contacts],
    }
    if ext.gravity is not None:
        data["gravity"] = ext.gravity
    if ext.description is not None:
        data["description"] = ext.description
    return data


__all__ = ["Body", "model_data", "standing"]
