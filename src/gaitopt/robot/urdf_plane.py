"""The sagittal plane of a URDF robot: URDF vectors as gaitopt's (x, y, z), and the documented
rule for a gaitopt link's direction and length from its points (``docs/urdf.md``).

With the common joint axis ``y`` gaitopt (x, y, z) = URDF (x, z, -y); with ``x``,
gaitopt (x, y, z) = URDF (-y, z, -x) (see :mod:`gaitopt.robot.urdf`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: Coordinates smaller than this (m) computed through a frame rotation are taken as exactly 0.
SNAP = 1e-12
#: Tolerance on a joint axis being the common axis (a unit vector).
AXIS_TOL = 1e-9

#: Rows: gaitopt x, y, z as URDF vectors, for each common axis.
PLANE = {"y": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
         "x": np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])}
#: Which URDF coordinates of a link frame a ``--contact`` point gives, for each common axis.
IN_PLANE = {"y": (0, 2), "x": (1, 2)}
#: The rows of a :data:`PLANE` matrix: the plane's x and y, and its normal (gaitopt z).
IN_PLANE_ROWS, NORMAL = slice(0, 2), 2


def is_identity(rot: np.ndarray) -> bool:
    """Whether a rotation matrix is exactly the identity (no rounding went into it)."""
    return bool(np.array_equal(rot, np.eye(3)))


def link_point(p: Sequence[float] | np.ndarray, direction: str) -> list[float]:
    """gaitopt link-frame coordinates (x, y) as ``[along, across]`` for a link direction
    (``+ 0.0`` turns ``-0.0`` into ``0.0``)."""
    x, y = float(p[0]), float(p[1])
    return [-y + 0.0, x + 0.0] if direction == "down" else [y + 0.0, -x + 0.0]


def direction_and_length(points: list[np.ndarray], com: np.ndarray,
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
    below = max([-float(p[1]) for p in points if p[1] < 0.0], default=0.0)
    above = max([float(p[1]) for p in points if p[1] > 0.0], default=0.0)
    height = float(com[1])
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
