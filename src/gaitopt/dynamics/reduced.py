"""The Reduced Dynamics Algorithm for a biped (paper appendices 2 and 3).

With tips held on the ground the 7 generalized coordinates are not independent. The walking
problem integrates *independent* coordinates only:

* single support on leg ``s`` (leg ``w`` swinging), 5 coordinates, 10 states::

      z = [r, alpha, torso, hip_w, knee_w]

* double support (both tips held), 3 coordinates, 6 states::

      z = [r, alpha, torso]

``(r, alpha)`` are polar coordinates of the hip about the stance tip ``p_s``: ``r`` is the
hip-to-tip distance (m) and ``alpha`` the absolute angle of the hip-to-tip line, measured like
every link angle from straight down, CCW positive, so that (world frame)::

      p_hip = p_s + r (-sin alpha, cos alpha)

(``alpha > 0``: the tip is ahead of the hip). A box bound on ``r`` keeps the hip within the
stance leg's reach (paper section 3.5). The dependent coordinates of every held leg come from
the two-link inverse kinematics with the knee bending backwards (``knee <= 0``, paper eqs.
14-16), its velocities from differentiating the same relations (the tip velocity is zero), and
the independent accelerations from the Contact Algorithm's solution (appendix 2, step 3):
``zdd`` are the entries of ``qdd`` of the independent joint coordinates and, for the hip, the
polar components of the hip acceleration::

      rdd     = a_hip . e_r + r alphad^2,           e_r     = (-sin alpha,  cos alpha)
      alphadd = (a_hip . e_alpha - 2 rd alphad) / r, e_alpha = (-cos alpha, -sin alpha)

Every function runs on floats and on CasADi symbols (one code path). With numbers, a hip out of
a leg's reach raises :class:`ReachError` instead of returning NaN.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.backend import (
    Scalar,
    Scalars,
    as_scalars,
    atan2,
    cos,
    is_symbolic,
    sin,
    sqrt,
    vector,
)
from gaitopt.dynamics.contact import contact_dynamics
from gaitopt.robot.biped import Leg, reduced_biped
from gaitopt.robot.model import BASE_ANGLE, BASE_POSITION, BASE_X, BASE_Y, RobotModel

#: Names of the independent coordinates, with ``{w}`` the swing leg's number.
SINGLE_SUPPORT_COORDINATES = ("r", "alpha", "torso", "hip_{w}", "knee_{w}")
DOUBLE_SUPPORT_COORDINATES = ("r", "alpha", "torso")
N_SINGLE = len(SINGLE_SUPPORT_COORDINATES)
N_DOUBLE = len(DOUBLE_SUPPORT_COORDINATES)



class ReachError(ValueError):
    """A hip position no leg configuration can reach (numeric evaluation only)."""


@dataclass(frozen=True)
class LegJoints:
    """Joint angles (rad) and rates (rad/s) of a leg whose tip is held fixed."""

    hip: Scalar
    knee: Scalar
    hip_rate: Scalar
    knee_rate: Scalar


@dataclass(frozen=True)
class ReducedSolution:
    """Result of the reduced forward dynamics.

    Attributes:
        zdd: independent accelerations, shape ``(n,)`` like ``z``.
        q, qd, qdd: the full generalized coordinates, velocities, accelerations ``(nq,)``.
        forces: contact forces of the ground on the held tips, world frame,
            ``[fx_s, fy_s(, fx_f, fy_f)]`` (N).
    """

    zdd: Any
    q: Any
    qd: Any
    qdd: Any
    forces: Any


def hip_from_polar(p_tip: Sequence[Scalar], r: Scalar, alpha: Scalar, rd: Scalar,
                   alphad: Scalar) -> tuple[Scalars, Scalars]:
    """World position (m) and velocity (m/s) of the hip from polar coordinates about a tip."""
    s, c = sin(alpha), cos(alpha)
    p_hip = [p_tip[0] - r * s, p_tip[1] + r * c]
    v_hip = [-rd * s - r * alphad * c, rd * c - r * alphad * s]
    return p_hip, v_hip


def polar_from_hip(p_tip: Sequence[Scalar], p_hip: Sequence[Scalar],
                   v_hip: Sequence[Scalar]) -> tuple[Scalar, Scalar, Scalar, Scalar]:
    """``(r, alpha, rd, alphad)`` of the hip about a tip (inverse of :func:`hip_from_polar`)."""
    dx, dy = p_hip[0] - p_tip[0], p_hip[1] - p_tip[1]
    r = sqrt(dx * dx + dy * dy)
    alpha = atan2(-dx, dy)
    rd = (dx * v_hip[0] + dy * v_hip[1]) / r
    alphad = (-dy * v_hip[0] + dx * v_hip[1]) / (r * r)
    return r, alpha, rd, alphad


def leg_inverse_kinematics(leg: Leg, p_hip: Sequence[Scalar], v_hip: Sequence[Scalar],
                           p_tip: Sequence[Scalar], torso: Scalar,
                           torso_rate: Scalar) -> LegJoints:
    """Hip and knee angles and rates of a two-link leg whose tip is fixed at ``p_tip``.

    With ``d = p_tip - p_hip = rho (sin gamma, -cos gamma)`` (``gamma``: absolute angle of the
    hip-to-tip line), the law of cosines gives ``D = cos(knee) = (rho^2 - a1^2 - a2^2) /
    (2 a1 a2)`` and the knee bending backwards ``knee = atan2(-sqrt(1 - D^2), D)`` (paper eqs.
    14-15); the thigh is ``beta = atan2(a2 sin knee, a1 + a2 cos knee)`` behind the hip-to-tip
    line (eq. 16), so ``hip = gamma - beta - torso``. Rates follow by differentiation with the
    tip at rest: ``knee_rate = rho rho_rate / (a1 a2 sin(-knee))`` and
    ``beta_rate = a2 (a2 + a1 cos knee) / rho^2 * knee_rate``.
    """
    a1, a2 = leg.thigh_length, leg.shank_length
    dx, dy = p_tip[0] - p_hip[0], p_tip[1] - p_hip[1]
    rho2 = dx * dx + dy * dy
    cos_knee = (rho2 - a1 * a1 - a2 * a2) / (2.0 * a1 * a2)
    if not is_symbolic(cos_knee) and not -1.0 < cos_knee < 1.0:
        rho = float(rho2) ** 0.5
        raise ReachError(
            f"hip-to-tip distance {rho:.4f} m of leg {leg.contact!r} is outside the leg's "
            f"reach ({abs(a1 - a2):.4f} m, {a1 + a2:.4f} m) exclusive: no knee angle exists")
    sin_minus_knee = sqrt(1.0 - cos_knee * cos_knee)  # = sin(-knee) > 0
    knee = atan2(-sin_minus_knee, cos_knee)
    sin_knee = -sin_minus_knee
    beta = atan2(a2 * sin_knee, a1 + a2 * cos_knee)
    gamma = atan2(dx, -dy)
    hip = gamma - beta - torso
    # Rates: the tip is at rest, so d_dot = -v_hip.
    ddx, ddy = -v_hip[0], -v_hip[1]
    rho_rho_rate = dx * ddx + dy * ddy
    knee_rate = rho_rho_rate / (a1 * a2 * sin_minus_knee)
    beta_rate = a2 * (a2 + a1 * cos_knee) / rho2 * knee_rate
    gamma_rate = (-dy * ddx + dx * ddy) / rho2
    hip_rate = gamma_rate - beta_rate - torso_rate
    return LegJoints(hip=hip, knee=knee, hip_rate=hip_rate, knee_rate=knee_rate)


def _full_state(model: RobotModel, p_hip: Scalars, v_hip: Scalars, torso: Scalar,
                torso_rate: Scalar, joints: dict[int, tuple[Scalar, Scalar]]) -> tuple[Any, Any]:
    q: Scalars = [0.0] * model.nq
    qd: Scalars = [0.0] * model.nq
    q[BASE_X], q[BASE_Y], q[BASE_ANGLE] = p_hip[0], p_hip[1], torso
    qd[BASE_X], qd[BASE_Y], qd[BASE_ANGLE] = v_hip[0], v_hip[1], torso_rate
    for index, (angle, rate) in joints.items():
        q[index], qd[index] = angle, rate
    return vector(q), vector(qd)


def single_support_state(model: RobotModel, stance: int, z: Any, zd: Any,
                         p_stance: Sequence[float] = (0.0, 0.0)) -> tuple[Any, Any]:
    """Full ``(q, qd)`` from single-support coordinates ``z, zd`` (5,) on leg ``stance`` (0/1)
    whose tip is at ``p_stance`` (world, m)."""
    legs = reduced_biped(model).legs
    r, alpha, torso, hip_w, knee_w = as_scalars(z, N_SINGLE, "z")
    rd, alphad, torso_rate, hip_w_rate, knee_w_rate = as_scalars(zd, N_SINGLE, "zd")
    p_hip, v_hip = hip_from_polar(p_stance, r, alpha, rd, alphad)
    s_leg, w_leg = legs[stance], legs[1 - stance]
    s = leg_inverse_kinematics(s_leg, p_hip, v_hip, p_stance, torso, torso_rate)
    return _full_state(model, p_hip, v_hip, torso, torso_rate, {
        s_leg.hip_index: (s.hip, s.hip_rate), s_leg.knee_index: (s.knee, s.knee_rate),
        w_leg.hip_index: (hip_w, hip_w_rate), w_leg.knee_index: (knee_w, knee_w_rate)})


def double_support_state(model: RobotModel, stance: int, z: Any, zd: Any,
                         p_stance: Sequence[Scalar], p_front: Sequence[Scalar]
                         ) -> tuple[Any, Any]:
    """Full ``(q, qd)`` from double-support coordinates ``z, zd`` (3,): hip polar about the
    tip of leg ``stance`` at ``p_stance``, the other tip held at ``p_front`` (world, m)."""
    legs = reduced_biped(model).legs
    r, alpha, torso = as_scalars(z, N_DOUBLE, "z")
    rd, alphad, torso_rate = as_scalars(zd, N_DOUBLE, "zd")
    p_hip, v_hip = hip_from_polar(p_stance, r, alpha, rd, alphad)
    s_leg, f_leg = legs[stance], legs[1 - stance]
    s = leg_inverse_kinematics(s_leg, p_hip, v_hip, p_stance, torso, torso_rate)
    f = leg_inverse_kinematics(f_leg, p_hip, v_hip, p_front, torso, torso_rate)
    return _full_state(model, p_hip, v_hip, torso, torso_rate, {
        s_leg.hip_index: (s.hip, s.hip_rate), s_leg.knee_index: (s.knee, s.knee_rate),
        f_leg.hip_index: (f.hip, f.hip_rate), f_leg.knee_index: (f.knee, f.knee_rate)})


def single_support_coordinates(model: RobotModel, stance: int, q: Any, qd: Any,
                               p_stance: Sequence[Scalar] = (0.0, 0.0)) -> tuple[Any, Any]:
    """Single-support coordinates ``(z, zd)`` of a full state (the inverse map)."""
    legs = reduced_biped(model).legs
    qs = as_scalars(q, model.nq, "q")
    qds = as_scalars(qd, model.nq, "qd")
    r, alpha, rd, alphad = polar_from_hip(p_stance, qs[BASE_POSITION], qds[BASE_POSITION])
    w = legs[1 - stance]
    z = [r, alpha, qs[BASE_ANGLE], qs[w.hip_index], qs[w.knee_index]]
    zd = [rd, alphad, qds[BASE_ANGLE], qds[w.hip_index], qds[w.knee_index]]
    return vector(z), vector(zd)


def double_support_coordinates(model: RobotModel, stance: int, q: Any, qd: Any,
                               p_stance: Sequence[Scalar] = (0.0, 0.0)) -> tuple[Any, Any]:
    """Double-support coordinates ``(z, zd)`` of a full state (the inverse map)."""
    reduced_biped(model)
    qs = as_scalars(q, model.nq, "q")
    qds = as_scalars(qd, model.nq, "qd")
    r, alpha, rd, alphad = polar_from_hip(p_stance, qs[BASE_POSITION], qds[BASE_POSITION])
    return vector([r, alpha, qs[BASE_ANGLE]]), vector([rd, alphad, qds[BASE_ANGLE]])


def polar_accelerations(r: Scalar, alpha: Scalar, rd: Scalar, alphad: Scalar,
                        a_hip: Sequence[Scalar]) -> tuple[Scalar, Scalar]:
    """``(rdd, alphadd)`` from the hip acceleration ``a_hip`` (world, m/s^2)."""
    s, c = sin(alpha), cos(alpha)
    a_r = -s * a_hip[0] + c * a_hip[1]
    a_alpha = -c * a_hip[0] - s * a_hip[1]
    return a_r + r * alphad * alphad, (a_alpha - 2.0 * rd * alphad) / r


def single_support_dynamics(model: RobotModel, stance: int, z: Any, zd: Any, tau: Any,
                            p_stance: Sequence[float] = (0.0, 0.0)) -> ReducedSolution:
    """Reduced forward dynamics in single support on leg ``stance``.

    ``tau`` (nq,) are the generalized forces of the actuators (see
    ``gaitopt.dynamics.actuation``), with the stance tip held: step 2 of the algorithm solves
    the Contact Algorithm for ``qdd`` and the contact force, step 3 reads ``zdd`` off ``qdd``.
    """
    legs = reduced_biped(model).legs
    q, qd = single_support_state(model, stance, z, zd, p_stance)
    sol = contact_dynamics(model, q, qd, tau, [legs[stance].contact])
    zs, zds = as_scalars(z, N_SINGLE, "z"), as_scalars(zd, N_SINGLE, "zd")
    qdd = as_scalars(sol.qdd, model.nq, "qdd")
    rdd, alphadd = polar_accelerations(zs[0], zs[1], zds[0], zds[1], qdd[BASE_POSITION])
    w = legs[1 - stance]
    zdd = vector([rdd, alphadd, qdd[BASE_ANGLE], qdd[w.hip_index], qdd[w.knee_index]])
    return ReducedSolution(zdd=zdd, q=q, qd=qd, qdd=sol.qdd, forces=sol.forces)


def double_support_dynamics(model: RobotModel, stance: int, z: Any, zd: Any, tau: Any,
                            p_stance: Sequence[Scalar], p_front: Sequence[Scalar]
                            ) -> ReducedSolution:
    """Reduced forward dynamics in double support (both tips held); forces are ordered
    ``[stance tip, front tip]``."""
    legs = reduced_biped(model).legs
    q, qd = double_support_state(model, stance, z, zd, p_stance, p_front)
    sol = contact_dynamics(model, q, qd, tau, [legs[stance].contact, legs[1 - stance].contact])
    zs, zds = as_scalars(z, N_DOUBLE, "z"), as_scalars(zd, N_DOUBLE, "zd")
    qdd = as_scalars(sol.qdd, model.nq, "qdd")
    rdd, alphadd = polar_accelerations(zs[0], zs[1], zds[0], zds[1], qdd[BASE_POSITION])
    zdd = vector([rdd, alphadd, qdd[BASE_ANGLE]])
    return ReducedSolution(zdd=zdd, q=q, qd=qd, qdd=sol.qdd, forces=sol.forces)
