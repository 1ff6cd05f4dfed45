"""The joint-space mass matrix by the composite-rigid-body algorithm (CRBA).

Composite inertias ``Ic_k = I_k + sum_children X_c^T Ic_c X_c`` (inward pass), then
``M[k, k] = S_k^T Ic_k S_k`` and, walking from ``k`` to the root with ``F = X_j^T F``
(``F = Ic_k S_k`` at first), ``M[parent, k] = M[k, parent] = S_parent^T F``.

``M`` has shape ``(nq, nq)``, rows and columns in the order of ``q``; it is symmetric positive
definite (kg on ``x``, ``y``; kg m^2 on angles; kg m off-diagonal between them).
"""

from __future__ import annotations

from typing import Any

from gaitopt.dynamics.backend import Scalars, matrix
from gaitopt.dynamics.kinematics import coordinates
from gaitopt.dynamics.spatial import (
    RigidInertia,
    add_inertia,
    force_to_parent,
    inertia_times,
    inertia_to_parent,
    unit3,
)
from gaitopt.dynamics.tree import bodies, joint_transforms
from gaitopt.robot.model import RobotModel


def crba_scalars(model: RobotModel, q: Scalars) -> list[Scalars]:
    """:func:`crba` on a scalar list; the result is a list of rows."""
    tree = bodies(model)
    x = joint_transforms(tree, q)
    n = len(tree)
    composite: list[RigidInertia] = [body.inertia for body in tree]
    for k in reversed(range(n)):
        p = tree[k].parent
        if p >= 0:
            composite[p] = add_inertia(composite[p], inertia_to_parent(x[k], composite[k]))
    m: list[Scalars] = [[0.0] * n for _ in range(n)]
    for k in range(n):
        f = inertia_times(composite[k], unit3(tree[k].axis))
        m[k][k] = f[tree[k].axis]
        j = k
        while tree[j].parent >= 0:
            f = force_to_parent(x[j], f)
            j = tree[j].parent
            m[j][k] = m[k][j] = f[tree[j].axis]
    return m


def crba(model: RobotModel, q: Any) -> Any:
    """The mass matrix ``M(q)`` ``(nq, nq)``."""
    return matrix(crba_scalars(model, coordinates(model, q)))
