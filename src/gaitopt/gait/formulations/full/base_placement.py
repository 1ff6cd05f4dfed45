"""The floating base placed by a held point: fewer unknowns and rows, the same optimum.

In a phase that pins a point on the ground, the full problem's knots after the first need
not carry the base's translation ``x, y`` (m) and its rates (m/s) as variables, nor the
point's held-point rows: when ``x, y`` translate the whole tree (:func:`base_point`), they
are the values that put the point at its ground point at rest (:func:`placed_base`), 4
fewer unknowns and rows per knot (:class:`~gaitopt.ocp.problem.KnotStates`). The world frame
has ``x`` forward along the ground and ``y`` up, the ground at ``y = 0``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import casadi as ca
import numpy as np

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.kinematics import contact_position, contact_velocity
from gaitopt.gait.formulations.step_parameters import STEP_LENGTH_INDEX
from gaitopt.gait.sequence.contact_sequence import ContactSequence
from gaitopt.robot.model import RobotModel

#: The floating base's translation (m) and its rates (m/s), placed by a pinned point.
BASE_STATES = ("x", "y", "x_rate", "y_rate")


def base_point(model: RobotModel, held: Sequence[str]) -> str | None:
    """The first point of ``held`` pinned on the ground (``name``, not ``name:y``) if the
    model's first two coordinates ``x, y`` translate the whole tree (then every point's
    position is ``(x, y)`` plus a function of the other coordinates, and its velocity
    ``(x_rate, y_rate)`` plus one of the others: checked at a random state), else None."""
    pinned = [c for c in held if ":" not in c]
    if not pinned or tuple(model.coordinate_names[:2]) != ("x", "y"):
        return None
    nq = model.nq
    q, qd = ca.SX.sym("q", nq), ca.SX.sym("qd", nq)
    qv, qdv = vector(as_scalars(q, nq, "q")), vector(as_scalars(qd, nq, "qd"))
    fn = ca.Function("point", [q, qd], [contact_position(model, qv, pinned[0]),
                                        contact_velocity(model, qv, qdv, pinned[0])])
    rng = np.random.default_rng(0)
    q0, qd0, shift = rng.normal(size=nq), rng.normal(size=nq), np.zeros(nq)
    shift[:2] = rng.normal(size=2)
    p0, v0 = (np.asarray(v).ravel() for v in fn(q0, qd0))
    p1, v1 = (np.asarray(v).ravel() for v in fn(q0 + shift, qd0 + shift))
    translates = np.allclose(p1 - p0, shift[:2], atol=1e-12) and np.allclose(
        v1 - v0, shift[:2], atol=1e-12)
    return pinned[0] if translates else None


def placed_base(model: RobotModel, seq: ContactSequence, point: str, phase: int
                ) -> Callable[[Any, Any], Any]:
    """``(x, p) -> (x, y, x_rate, y_rate)`` (m, m/s) of the base that puts ``point`` at its
    ground point ``(a L + b, 0)`` of phase ``phase`` at rest: minus its position and
    velocity with the base at 0."""
    nq = model.nq

    def fn(x: Any, p: Any) -> Any:
        xs = as_scalars(x, 2 * nq, "x")
        q = vector([0.0, 0.0] + list(xs[2:nq]))
        qd = vector([0.0, 0.0] + list(xs[nq + 2:]))
        pos = as_scalars(contact_position(model, q, point), 2, "p")
        vel = as_scalars(contact_velocity(model, q, qd, point), 2, "v")
        return vector([seq.ground_x(point, p[STEP_LENGTH_INDEX], phase) - pos[0], -pos[1], -vel[0],
                       -vel[1]])

    return fn
