"""Can this model walk at all? Checks of the model before any solve, each a one-line answer.

A model that cannot walk makes IPOPT fail after minutes with a diagnosis about torques and
contact forces; these checks say in one line what in the model prevents it and what to
change, before anything is solved (:func:`preflight`; ``gaitopt solve`` prints the first and
exits with status 2, writing no gait file):

1. **Unactuated leg joints** (:func:`unactuated_joints`): a joint on a leg (the chain from
   the base to a contact point) with a range of motion and no actuator: nothing moves the
   swing leg forward there (a hip without a motor), or holds the torso up.
2. **Legs that cannot reach the ground** (:func:`unreachable_ground`): within its joint
   limits and the torso bounds, a leg's first contact point cannot get below its hip
   (``max_q (y_hip - y_c) <= 0``: the leg cannot stand under the body).
3. **No step** (:func:`unplaceable_step`): the double-support pose of a short step, solved
   as a small inverse-kinematics problem for both orders of the legs: the first contact
   point of the rear leg at ``(0, 0)``, the front leg's at ``(s, 0)`` with ``s``
   :data:`SHORT_STEP` leg lengths, the hip midway (``x_hip = s / 2``: the symmetric
   double-support pose a walk passes through and the naive guesses start from) and above
   the ground, every contact point at ``y >= 0``, the torso within its bounds and every joint
   within its limits. If no such pose exists for one order, one leg can never be in front of
   the other: a hip range that allows only a backward swing (MuJoCo's Walker2d thigh range,
   seen in gaitopt's sign convention) at the torso angles allowed. (Kinematics decide: hips
   in ``[-2, 0]`` still put the front point ahead of the hip when the torso may lean back by
   about ``s / (2 l)`` rad or more, as the default +-0.8 rad allows; with the torso held
   within +-0.02 rad they cannot.)

The inverse kinematics is a bounded least-squares problem (Levenberg-Marquardt,
:func:`_least_squares`) from a few starts; a pose is found when its residual is below
:data:`PLACED` leg lengths.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from gaitopt.dynamics.kinematics import contact_position, point_position
from gaitopt.gait.model_defaults import legs_contacts
from gaitopt.gait.model_scale import leg_length
from gaitopt.gait.options import GaitOptions, GaitOptionsError
from gaitopt.robot.model import BASE_ANGLE, BASE_X, BASE_Y, RobotModel

Array = NDArray[np.float64]

#: The step of the placement check, in characteristic leg lengths ``l``
#: (:func:`gaitopt.gait.model_scale.leg_length`): 0.1 m on the five-link biped, whose
#: optimal steps are 0.1-0.12 m.
SHORT_STEP = 0.1
#: Largest residual (in leg lengths) of a pose that counts as placed: 1 mm on 1 m legs.
PLACED = 1e-3
#: Most Levenberg-Marquardt steps of one inverse-kinematics solve (:func:`_least_squares`).
MAX_STEPS = 300


class UnwalkableModelError(GaitOptionsError):
    """Something in the model prevents walking (:func:`preflight`); the message says what
    and what to change."""


def _leg_chains(model: RobotModel) -> list[tuple[str, tuple[int, ...]]]:
    """(first contact point, link indices from below the base to its link) of each leg."""
    out = []
    for points in legs_contacts(model):
        chain = model.chain(model.link_index(model.contact(points[0]).link))[1:]
        out.append((points[0], chain))
    return out


def unactuated_joints(model: RobotModel) -> list[str]:
    """A line for each joint on a leg that can move (``lower < upper``) but has no actuator."""
    actuated = {a.joint for a in model.actuators if a.joint is not None}
    out, seen = [], set()
    for point, chain in _leg_chains(model):
        for i in chain:
            joint = model.links[i].joint
            if joint is None or joint.name in actuated or joint.name in seen:
                continue
            if joint.limits[1] > joint.limits[0]:
                seen.add(joint.name)
                lo, hi = joint.limits
                out.append(f"model {model.name!r}: joint {joint.name!r} on the leg of "
                           f"{point!r} (range [{lo:g}, {hi:g}] rad) has no actuator, so "
                           "nothing can swing that leg or hold the body on it; add one to the "
                           f"model's actuators, e.g. {{name: {joint.name}, joint: "
                           f"{joint.name}, limits: [-TAU, TAU]}} (N m)")
    return out


def _bounds(model: RobotModel, torso: tuple[float, float]) -> tuple[Array, Array]:
    lo = np.array([-np.inf, -np.inf, torso[0]] + [j.limits[0] for j in model.joints])
    hi = np.array([np.inf, np.inf, torso[1]] + [j.limits[1] for j in model.joints])
    return lo, hi


def _starts(model: RobotModel, lo: Array, hi: Array) -> list[Array]:
    """Starting poses inside the box: every joint at 0, at the middle of its range, and at a
    quarter and three quarters of it (clipped, finite; an unbounded side of a joint's range
    counts as -pi or pi, where a revolute joint has turned once)."""
    out = []
    low = np.where(np.isfinite(lo), lo, np.minimum(-np.pi, hi))
    high = np.where(np.isfinite(hi), hi, np.maximum(np.pi, lo))
    for frac in (None, 0.5, 0.25, 0.75):
        q = np.zeros(model.nq)
        if frac is not None:
            q[3:] = low[3:] + frac * (high[3:] - low[3:])
        q[2] = 0.0
        out.append(np.clip(q, np.where(np.isfinite(lo), lo, -1e9),
                           np.where(np.isfinite(hi), hi, 1e9)))
    return out


class _Points:
    """The world positions (m) of every contact point and every leg's hip as compiled
    functions of ``q`` (nq,), with their Jacobians: the checks evaluate them thousands of
    times."""

    def __init__(self, model: RobotModel) -> None:
        import casadi as ca

        q = ca.SX.sym("q", model.nq)
        rows = [contact_position(model, q, c.name) for c in model.contacts]
        for _, chain in _leg_chains(model):
            root = model.links[chain[0]]
            at = root.joint.at if root.joint is not None else (0.0, 0.0)
            rows.append(point_position(model, q, model.parent_index(chain[0]), at))
        p = ca.vertcat(*rows)
        self.index = {c.name: i for i, c in enumerate(model.contacts)}
        self.n_contacts = len(model.contacts)
        self._f = ca.Function("points", [q], [p, ca.jacobian(p, q)])

    def __call__(self, q: Array) -> tuple[Array, Array]:
        """Positions ``(n_points, 2)`` (contacts in model order, then the hips by leg) and
        their Jacobian ``(2 n_points, nq)``."""
        p, jac = self._f(q)
        return np.asarray(p, dtype=float).reshape(-1, 2), np.asarray(jac, dtype=float)


@functools.lru_cache(maxsize=16)
def _points(model: RobotModel) -> _Points:
    return _Points(model)


def _least_squares(residual: Callable[[Array], tuple[Array, Array]], q0: Array, lo: Array,
                   hi: Array, enough: float = 0.0) -> Array:
    """A local minimum of ``|r(q)|^2`` within ``lo <= q <= hi``, or the first point where it
    is at most ``enough``: Levenberg-Marquardt steps on the variables not held at a bound by
    the gradient, clipped into the box (a few hundred small systems; SciPy's optimizer takes
    longer to import than these checks to run)."""
    q, mu = np.clip(q0, lo, hi), 1e-3
    r, jac = residual(q)
    cost = float(r @ r)
    for _ in range(MAX_STEPS):
        grad = jac.T @ r
        free = ~(((q <= lo) & (grad > 0.0)) | ((q >= hi) & (grad < 0.0)))
        jf = jac[:, free]
        step = np.zeros_like(q)
        step[free] = -np.linalg.solve(jf.T @ jf + mu * np.eye(jf.shape[1]), jf.T @ r)
        trial = np.clip(q + step, lo, hi)
        r_trial, jac_trial = residual(trial)
        cost_trial = float(r_trial @ r_trial)
        if cost_trial < cost:
            done = cost - cost_trial <= 1e-15 * (1.0 + cost)
            q, r, jac, cost, mu = trial, r_trial, jac_trial, cost_trial, max(mu / 3.0, 1e-12)
            if done or cost <= enough:
                break
        else:
            mu *= 4.0
            if mu > 1e10:
                break
    return q


def _solve(residual: Callable[[Array], tuple[Array, Array]], starts: list[Array], lo: Array,
           hi: Array) -> tuple[Array, float]:
    """The least-squares pose of smallest residual norm over ``starts`` (``residual``
    returns the residual and its Jacobian)."""
    best, best_norm = starts[0], np.inf
    for q0 in starts:
        q = _least_squares(residual, q0, lo, hi)
        norm = float(np.linalg.norm(residual(q)[0]))
        if norm < best_norm:
            best, best_norm = q, norm
        if best_norm <= 1e-9:
            break
    return best, best_norm


def _ranges(model: RobotModel, chain: tuple[int, ...]) -> str:
    joints = [model.links[i].joint for i in chain]
    return ", ".join(f"{j.name} [{j.limits[0]:g}, {j.limits[1]:g}]" for j in joints
                     if j is not None)


def unreachable_ground(model: RobotModel, torso: tuple[float, float]) -> list[str]:
    """A line for each leg whose first contact point cannot get below its hip with the
    torso within ``torso`` (rad) and the joints within their limits."""
    lo, hi = _bounds(model, torso)
    lo[BASE_X], hi[BASE_X], lo[BASE_Y], hi[BASE_Y] = 0.0, 0.0, 0.0, 0.0
    points = _points(model)
    out = []
    for leg, (point, chain) in enumerate(_leg_chains(model)):
        rows = (points.index[point], points.n_contacts + leg)
        # Least squares of (y_point - y_hip + depth): minimises the point's height above the
        # hip while it stays above -depth; depth is twice the farthest the point can be
        # from the hip (the joint offsets down the chain and the point's offset).
        offsets = [model.links[i].joint for i in chain[1:]]
        reach = float(sum(np.hypot(*j.at) for j in offsets if j is not None)
                      + np.hypot(*model.contact(point).at))
        depth = 2.0 * reach

        def height(q: Array, rows: tuple[int, int] = rows, depth: float = depth
                   ) -> tuple[Array, Array]:
            p, jac = points(q)
            value = np.array([p[rows[0], 1] - p[rows[1], 1] + depth])
            return value, (jac[2 * rows[0] + 1] - jac[2 * rows[1] + 1])[None, :]

        # Enough: the point below the hip by a thousandth of its reach.
        enough = (depth - PLACED * reach) ** 2
        best = np.inf
        for q0 in _starts(model, lo, hi):
            q = _least_squares(height, q0, lo, hi, enough)
            best = min(best, float(height(q, depth=0.0)[0][0]))
            if best < 0.0:
                break
        if best >= 0.0:
            out.append(f"model {model.name!r}: the leg of {point!r} cannot reach the ground: "
                       f"within its joint limits ({_ranges(model, chain)} rad) and the torso "
                       f"bounds [{torso[0]:g}, {torso[1]:g}] rad that point stays "
                       f"{best:.3g} m above the hip; widen the ranges so the leg can hang "
                       "down (all angles 0 is a straight leg pointing down)")
    return out


def unplaceable_step(model: RobotModel, torso: tuple[float, float],
                     leg_length: float) -> list[str]:
    """A line for each order of the legs in which no double-support pose of a step of
    :data:`SHORT_STEP` ``leg_length`` exists (module docstring, check 3)."""
    legs = _leg_chains(model)
    if len(legs) != 2:
        return []
    step = SHORT_STEP * leg_length
    lo, hi = _bounds(model, torso)
    # The hip midway between the points (within a micrometre on 1 m legs: the bounds of
    # least_squares must differ), above the ground.
    lo[BASE_X], hi[BASE_X] = step / 2.0 - 1e-6 * leg_length, step / 2.0 + 1e-6 * leg_length
    lo[BASE_Y] = 0.0
    points = _points(model)
    n = points.n_contacts
    out = []
    for (front, front_chain), (rear, _) in (legs, legs[::-1]):
        f, r = points.index[front], points.index[rear]

        def residual(q: Array, f: int = f, r: int = r) -> tuple[Array, Array]:
            """Rear point at the origin, front point at ``(s, 0)``, no point below the
            ground; and the Jacobian."""
            p, jac = points(q)
            below = p[:n, 1] < 0.0
            heights = np.where(below, p[:n, 1], 0.0)
            d_heights = jac[1:2 * n:2] * below[:, None]
            value = np.concatenate([p[r], p[f] - np.array([step, 0.0]), heights])
            return value, np.vstack([jac[2 * r:2 * r + 2], jac[2 * f:2 * f + 2], d_heights])

        starts = []
        for q0 in _starts(model, lo, hi):
            q0 = q0.copy()
            q0[BASE_X], q0[BASE_Y], q0[BASE_ANGLE] = step / 2.0, leg_length, 0.0
            starts.append(q0)
        _, norm = _solve(residual, starts, lo, hi)
        if norm > PLACED * leg_length:
            out.append(f"model {model.name!r}: the leg of {front!r} can never be in front of "
                       f"the leg of {rear!r}: no pose within the joint limits "
                       f"({_ranges(model, front_chain)} rad) and the torso bounds "
                       f"[{torso[0]:g}, {torso[1]:g}] rad puts {front!r} {step:.3g} m ahead "
                       f"of {rear!r} on the ground with the hip midway (the best misses "
                       f"by {norm:.3g} m); widen the hip range forward (positive angles swing "
                       "the thigh forward)")
    return out


@functools.lru_cache(maxsize=32)
def _preflight(model: RobotModel, torso: tuple[float, float]) -> tuple[str, ...]:
    problems = unactuated_joints(model) + unreachable_ground(model, torso)
    if problems:
        return tuple(problems)
    try:
        length = leg_length(model)
    except ValueError as exc:
        return (str(exc),)
    return tuple(unplaceable_step(model, torso, length))


def preflight(model: RobotModel, options: GaitOptions) -> tuple[str, ...]:
    """What in ``model`` prevents walking (module docstring): one line per problem naming it
    and what to change; empty if nothing does. Only models with two legs (one or two contact
    points each) are checked; others are left to the contact sequence's own checks.
    Cached per model and torso bounds."""
    if len(legs_contacts(model)) != 2:
        return ()
    t = options.torso_bounds
    return _preflight(model, (float(t[0]), float(t[1])))


def refuse_unwalkable(model: RobotModel, options: GaitOptions) -> None:
    """Raise :class:`UnwalkableModelError` with the first :func:`preflight` problem (and how
    many more there are)."""
    problems = preflight(model, options)
    if problems:
        more = (f" (and {len(problems) - 1} more problem(s) like it)"
                if len(problems) > 1 else "")
        raise UnwalkableModelError(problems[0] + more)
