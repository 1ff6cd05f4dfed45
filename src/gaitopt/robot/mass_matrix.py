"""Is a model well posed? Its joint-space mass matrix must be positive definite.

A link may be a point mass (inertia 0, as Drake and ROS files write them) or massless (a
frame), as long as every motion of the coordinates moves some mass or inertia; otherwise the
equations of motion ``M(q) qdd = ...`` have no unique solution. :func:`check_positive_definite`
is the last step of loading any model (``gaitopt.robot.schema``), whatever file it came from.

The mass matrix here is computed from its definition, the kinetic energy
``T = 1/2 qd^T M qd`` with ``M = sum_i m_i Jv_i^T Jv_i + I_i Jw_i^T Jw_i``, where for link
``i`` ``Jv_i`` (2, nq) is the Jacobian of its centre of mass (world frame, m per unit of q)
and ``Jw_i`` (1, nq) that of its absolute angle. This layer may not use ``gaitopt.dynamics``
(``docs/architecture.md``); its CRBA gives the same matrix, and the tests compare the two and
Pinocchio's.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from gaitopt.robot.errors import ModelError
from gaitopt.robot.model import BASE_ANGLE, BASE_X, BASE_Y, RobotModel

#: A mass matrix whose diagonally scaled form ``D^-1/2 M D^-1/2`` has an eigenvalue below this
#: is singular (rounding of an exactly singular one is ~1e-16).
SINGULAR_RTOL = 1e-12
#: Random poses tried besides the standing pose (all coordinates 0), and their seed.
RANDOM_POSES = 8
SEED = 20261202


def _rot(angle: float) -> NDArray[np.float64]:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def mass_matrix(model: RobotModel, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The joint-space mass matrix ``M(q)`` (nq, nq), kg and kg m^2, from the kinetic energy
    (module docstring). ``q`` (nq,) in the order of ``model.coordinate_names``.

    A link's lever arm about a joint above it is summed along the chain (joint offsets and the
    centre of mass, each turned into the world), never a difference of world positions, so a
    point mass on its own joint has exactly no arm.
    """
    n = len(model.links)
    angle = np.zeros(n)
    for i in range(n):  # parents come before their children
        p = model.parent_index(i)
        angle[i] = q[BASE_ANGLE] if p < 0 else angle[p] + q[model.coordinate_of_link(i)]
    rots = [_rot(a) for a in angle]
    # offset[i]: world vector from the parent's origin to link i's origin
    offset = [np.zeros(2) for _ in model.links]
    for i, link in enumerate(model.links):
        p = model.parent_index(i)
        if link.joint is not None:
            offset[i] = rots[p] @ np.array(model.links[p].local_point(*link.joint.at))
    out = np.zeros((model.nq, model.nq))
    for i, link in enumerate(model.links):
        chain = model.chain(i)
        jv = np.zeros((2, model.nq))
        jw = np.zeros(model.nq)
        jv[0, BASE_X], jv[1, BASE_Y] = 1.0, 1.0
        arm = rots[i] @ np.array(link.com_local)  # from link i's origin to its centre of mass
        for k in reversed(chain):  # from link i up to the base: rotations about origin k
            col = model.coordinate_of_link(k)
            jv[:, col] = (-arm[1], arm[0])
            jw[col] = 1.0
            arm = arm + offset[k]
        out += link.mass * jv.T @ jv + link.inertia * np.outer(jw, jw)
    return out


def sample_poses(model: RobotModel) -> list[NDArray[np.float64]]:
    """The standing pose (q = 0) and :data:`RANDOM_POSES` random poses (seeded: always the
    same) with the base angle in [-pi, pi] and each joint within its limits, at most one turn
    from its lower limit (M is periodic in every angle): [-pi, pi] without limits,
    [upper - 2 pi, upper] without a lower one."""
    rng = np.random.default_rng(SEED)
    lo = np.full(model.nq, -math.pi)
    hi = np.full(model.nq, math.pi)
    for i, link in enumerate(model.links[1:], start=1):
        assert link.joint is not None
        a, b = link.joint.limits
        c = model.coordinate_of_link(i)
        if math.isfinite(a):  # M is 2 pi periodic in each angle: one turn is enough
            lo[c], hi[c] = a, min(b, a + 2.0 * math.pi)
        elif math.isfinite(b):
            lo[c], hi[c] = b - 2.0 * math.pi, b
    lo[[BASE_X, BASE_Y]] = hi[[BASE_X, BASE_Y]] = 0.0  # M does not depend on x, y
    return [np.zeros(model.nq)] + [rng.uniform(lo, hi) for _ in range(RANDOM_POSES)]


def check_positive_definite(model: RobotModel, *, source: str = "<model>") -> None:
    """Refuse a model whose mass matrix is singular at one of :func:`sample_poses`.

    If every link has a mass > 0 and an inertia > 0 the matrix is positive definite at every
    pose (a motion with any joint or base rate turns some link, whose inertia then moves; one
    with only x, y rates moves the whole mass) and nothing is computed. Otherwise ``M`` is
    scaled by its diagonal ``D`` (``D^-1/2 M D^-1/2``, so light links are not mistaken for
    missing ones) and refused if an entry of ``D`` is 0 or an eigenvalue is below
    :data:`SINGULAR_RTOL`; the message names the coordinate (largest entry of the eigenvector).

    Raises:
        ModelError: one line naming ``source``, the link of the coordinate, and the pose.
    """
    if all(link.mass > 0.0 and link.inertia > 0.0 for link in model.links):
        return
    names = model.coordinate_names
    link_of = {model.coordinate_of_link(i): i for i in range(1, len(model.links))}
    for k, q in enumerate(sample_poses(model)):
        with np.errstate(over="ignore", invalid="ignore"):  # refused below if not finite
            m = mass_matrix(model, q)
        d = np.diag(m).copy()
        pose = "at the standing pose (q = 0)" if k == 0 else (
            f"at the pose q = [{', '.join(f'{x:.3g}' for x in q)}]")
        if not np.all(np.isfinite(m)):
            raise ModelError(source, "links", "inf", "masses and distances whose mass matrix "
                             "is finite", problem=f"the mass matrix overflows {pose}")
        if np.all(d > 0.0):
            scale = 1.0 / np.sqrt(d)
            values, vectors = np.linalg.eigh(m * np.outer(scale, scale))
            if values[0] > SINGULAR_RTOL:
                continue
            coordinate = int(np.argmax(np.abs(vectors[:, 0])))
        else:
            coordinate = int(np.argmin(d))
        name = names[coordinate]
        if coordinate not in link_of:
            path, what = "links[0]", f"the floating base's coordinate {name!r}"
        else:
            i = link_of[coordinate]
            path = f"links[{i}].joint"
            below = any(link.parent == model.links[i].name for link in model.links)
            what = (f"joint {name!r} (link {model.links[i].name!r}"
                    f"{' and the links below it' if below else ''})")
        raise ModelError(source, path, name, "a model whose mass matrix is positive definite: "
                         "every coordinate moves some mass or inertia (a point mass off its "
                         "joint, or a link inertia > 0)",
                         problem=f"the mass matrix is singular {pose}: {what} moves no mass "
                                 "or inertia")


__all__ = ["RANDOM_POSES", "SINGULAR_RTOL", "check_positive_definite", "mass_matrix",
           "sample_poses"]
