"""A synthetic, kinematically plausible gait of the five-link biped, for tests and figures.

It need not satisfy the dynamics. The hip moves forward at constant speed with a small
vertical bob; leg 1 stands at x = 0 (two-link inverse kinematics), leg 2 swings on a smooth
arc from x = -L to x = L during phase 1 and stands at x = L in phase 2; the torso sways a
little about upright. It is exactly periodic with the legs swapped and x shifted by L.
Velocities and accelerations are central finite differences of the phase's smooth formula.
World points come from a planar forward kinematics written here (independent of
``gaitopt.dynamics``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from gaitopt.gait.record.file import (
    Gait,
    GaitEvent,
    GaitPhase,
    GaitSamples,
)
from gaitopt.robot import RobotModel, load_model, model_to_dict
from gaitopt.robot.symmetry import swap_permutations
from gaitopt.study.summary import (
    SUMMARY_FILE,
    SpeedMode,
    SummaryRow,
    gait_relpath,
    summary_row,
    write_summary,
)

Array = NDArray[np.float64]
# q = [x, y, torso, hip_1, knee_1, hip_2, knee_2]; u = [hip_1, knee_1, ankle_1, hip_2, knee_2,
# ankle_2] (docs/conventions.md section 4).
X, Y, TORSO, HIP_1, KNEE_1, HIP_2, KNEE_2 = range(7)
U_HIP_1, U_KNEE_1, U_ANKLE_1, U_HIP_2, U_KNEE_2, U_ANKLE_2 = range(6)
HIP_HEIGHT = 0.92  # m, mean hip height
BOB = 0.01  # m, amplitude of the hip's vertical motion
SWAY = 0.05  # rad, amplitude of the torso's sway
CLEARANCE = 0.04  # m, swing tip height at mid swing


def down(phi: Array) -> Array:
    """Unit vector (..., 2) of a link at absolute angle phi measured from straight down."""
    return np.stack([np.sin(phi), -np.cos(phi)], axis=-1)


def forward_kinematics(model: RobotModel, q: Array) -> dict[str, Array]:
    """World points (N, 2) of hip, knees, tips and torso top for q (N, 7), five-link model."""
    l_thigh, l_shank = model.link("thigh_1").length, model.link("shank_1").length
    l_torso = model.link("torso").length
    hip = q[:, [X, Y]]
    torso = q[:, TORSO]
    out = {"hip": hip, "torso_top": hip + l_torso * np.stack([-np.sin(torso), np.cos(torso)], 1)}
    for leg, (h, k) in (("1", (HIP_1, KNEE_1)), ("2", (HIP_2, KNEE_2))):
        knee = hip + l_thigh * down(torso + q[:, h])
        out[f"knee_{leg}"] = knee
        out[f"tip_{leg}"] = knee + l_shank * down(torso + q[:, h] + q[:, k])
    return out


def leg_ik(model: RobotModel, hip: Array, tip: Array, torso: Array) -> tuple[Array, Array]:
    """Hip (relative to torso) and knee angles (knee <= 0) putting the tip at ``tip``.

    d = tip - hip; cos(knee) = (|d|^2 - l1^2 - l2^2) / (2 l1 l2), knee = -acos(.);
    thigh angle from down = atan2(dx, -dy) - atan2(l2 sin knee, l1 + l2 cos knee).
    """
    l1, l2 = model.link("thigh_1").length, model.link("shank_1").length
    d = tip - hip
    cos_knee = (np.sum(d**2, axis=-1) - l1**2 - l2**2) / (2 * l1 * l2)
    if np.any(cos_knee > 1.0):
        raise ValueError("tip out of reach")
    knee = -np.arccos(np.clip(cos_knee, -1.0, 1.0))
    thigh = np.arctan2(d[..., 0], -d[..., 1]) - np.arctan2(l2 * np.sin(knee),
                                                         l1 + l2 * np.cos(knee))
    return thigh - torso, knee


def synthetic_gait(*, speed: float = 0.5, step_length: float = 0.4,
                   single_support_fraction: float = 0.85, ankle: bool = True,
                   impulse: bool = True, torque_amplitude: float = 60.0,
                   knots: tuple[int, int] = (8, 5), n_samples: int = 101,
                   success: bool = True, model: RobotModel | None = None) -> Gait:
    """A plausible gait at ``speed`` (m/s) and ``step_length`` (m); see the module docstring.

    Torques are smooth fake profiles of amplitude ``torque_amplitude`` N m clipped to the
    actuator limits (an amplitude above the limits gives knots at the bounds). Without
    ``ankle`` the ankle torques are zero; without ``impulse`` the liftoff impulse is zero.
    """
    model = model or load_model("five-link")
    L, v = step_length, speed
    T = L / v
    T1 = single_support_fraction * T
    x0 = L / 2 - v * (T1 + T) / 2  # hip centred over the double-support stance
    t_mid = -x0 / v  # hip over the stance tip: top of the bob

    def q_of(t: Array, phase: int) -> Array:
        t = np.atleast_1d(t)
        hip = np.stack([x0 + v * t, HIP_HEIGHT + BOB * np.cos(2 * np.pi * (t - t_mid) / T)], 1)
        torso = SWAY * np.sin(2 * np.pi * t / T)
        tip1 = np.zeros_like(hip)
        if phase == 0:
            tau = t / T1
            s = (1 - np.cos(np.pi * tau)) / 2
            tip2 = np.stack([-L + 2 * L * s, CLEARANCE * np.sin(np.pi * tau)], 1)
        else:
            tip2 = np.tile([L, 0.0], (t.size, 1))
        h1, k1 = leg_ik(model, hip, tip1, torso)
        h2, k2 = leg_ik(model, hip, tip2, torso)
        return np.stack([hip[:, 0], hip[:, 1], torso, h1, k1, h2, k2], axis=1)

    def qd_of(t: Array, phase: int, h: float = 1e-6) -> Array:
        return (q_of(t + h, phase) - q_of(t - h, phase)) / (2 * h)

    def qdd_of(t: Array, phase: int, h: float = 1e-4) -> Array:
        return (q_of(t + h, phase) - 2 * q_of(t, phase) + q_of(t - h, phase)) / h**2

    lower = np.array([a.limits[0] for a in model.actuators])
    upper = np.array([a.limits[1] for a in model.actuators])

    def u_of(t: Array, phase: int) -> Array:
        t = np.atleast_1d(t)
        w = 2 * np.pi * t / T
        u = np.zeros((t.size, model.nu))
        u[:, U_HIP_1] = torque_amplitude * np.sin(w)
        u[:, U_KNEE_1] = 0.6 * torque_amplitude * np.cos(w)
        u[:, U_HIP_2] = -0.8 * torque_amplitude * np.sin(w + 0.5)
        u[:, U_KNEE_2] = 0.4 * torque_amplitude * np.cos(2 * w)
        if ankle:
            u[:, U_ANKLE_1] = 0.2 * torque_amplitude * np.sin(w)
            if phase == 1:
                u[:, U_ANKLE_2] = 0.2 * torque_amplitude * np.sin((t - T1) / (T - T1) * np.pi)
        return np.clip(u, lower, upper)

    m, g = model.total_mass, -model.gravity[1]

    def forces_of(t: Array, phase: int) -> dict[str, Array]:
        acc = qdd_of(t, phase)[:, [X, Y]]
        total = m * (acc + np.array([0.0, g]))
        if phase == 0:
            return {"tip_1": total}
        share = ((t - T1) / (T - T1))[:, None]
        return {"tip_1": (1 - share) * total, "tip_2": share * total}

    phases = []
    spans = ((0.0, T1, ("tip_1",), "single_support", (X, Y, TORSO, HIP_2, KNEE_2)),
             (T1, T, ("tip_1", "tip_2"), "double_support", (X, Y, TORSO)))
    for phase, (ta, tb, contacts, name, indep) in enumerate(spans):
        t = np.linspace(ta, tb, knots[phase])
        q, qd, qdd = q_of(t, phase), qd_of(t, phase), qdd_of(t, phase)
        coords = model.coordinate_names
        names = [coords[i] for i in indep] + [coords[i] + "_dot" for i in indep]
        phases.append(GaitPhase(
            name=name, contacts=contacts, t=t, q=q, qd=qd, qdd=qdd, u=u_of(t, phase),
            contact_forces=forces_of(t, phase), state_names=tuple(names),
            x=np.hstack([q[:, indep], qd[:, indep]]), xdot=np.hstack([qd[:, indep],
                                                                      qdd[:, indep]])))

    perm_q, _ = swap_permutations(model)
    q_end = q_of(np.array([T]), 1)[0]
    hip_to_tip = q_end[[X, Y]]  # the hip relative to tip 1 at (0, 0)
    p_mag = 25.0 * v if impulse else 0.0
    events = (
        GaitEvent(name="heel_strike", t=T1, leg="tip_2",
                  impulses={"tip_1": np.array([0.5, 1.0]), "tip_2": np.array([-3.0, 8.0])},
                  qd_before=qd_of(np.array([T1]), 0)[0], qd_after=qd_of(np.array([T1]), 1)[0]),
        GaitEvent(name="liftoff", t=T, leg="tip_1",
                  impulses={"tip_1": p_mag * hip_to_tip / np.linalg.norm(hip_to_tip)},
                  qd_before=qd_of(np.array([T]), 1)[0],
                  qd_after=qd_of(np.array([0.0]), 0)[0][perm_q]),
    )

    ts = np.linspace(0.0, T, n_samples)
    first = ts < T1

    def piecewise(fn: Callable[[Array, int], Array]) -> Array:
        return np.concatenate([fn(ts[first], 0), fn(ts[~first], 1)])

    q_s = piecewise(q_of)
    u_s = piecewise(u_of)
    samples = GaitSamples(t=ts, q=q_s, qd=piecewise(qd_of), u=u_s,
                          points=forward_kinematics(model, q_s))
    cost = (float(np.trapezoid(np.sum(u_s**2, axis=1), ts)) + p_mag**2) / L
    return Gait(
        model_data=model_to_dict(model),
        options={"ankle": ankle, "impulse": impulse, "speed": speed, "synthetic": True,
                 "single_support_fraction": single_support_fraction, "knots": list(knots)},
        parameters={"step_length": L, "speed": v, "step_time": T, "single_support_time": T1,
                    "liftoff_impulse": p_mag},
        cost={"value": cost, "formula": "(integral of u'u dt over the step + P^2) / step "
              "length (paper eq. 5)"},
        solver={"status": "Solve_Succeeded" if success else "Infeasible_Problem_Detected",
                "success": success, "iterations": 42, "wall_time_s": 0.25, "variables": 197,
                "equality_constraints": 131, "inequality_constraints": 23,
                "evaluations": {"state_equations": 1234, "boundary_constraints": 56,
                                "inequality_constraints": 789},
                "max_violation": 1e-9 if success else 0.3},
        phases=tuple(phases), events=events, samples=samples)


def synthetic_cost(v_m_min: float, *, ankle: bool, impulse: bool) -> float:
    """A made-up hyperbolic cost: 300/v + 2 v + 10, 30 % lower with the impulse, 5 % lower
    with ankle torques (minimum at v = sqrt(150) = 12.25 m/min)."""
    return (300.0 / v_m_min + 2.0 * v_m_min + 10.0) * (0.7 if impulse else 1.0) * (
        0.95 if ankle else 1.0)


def synthetic_step_length(v_m_min: float) -> float:
    return 0.05 + 0.008 * v_m_min


def synthetic_sweep(folder: Path, *, speeds_m_min: tuple[float, ...] = (3, 6, 12, 24, 36, 50),
                    free: bool = True, gaits: bool = True, n_samples: int = 41
                    ) -> list[SummaryRow]:
    """Write a sweep directory (summary.csv + gait files) of synthetic gaits; return its rows.

    Costs follow :func:`synthetic_cost`, step lengths :func:`synthetic_step_length`; the
    torque amplitude grows with speed and is 40 % lower with the impulse, so that walks near
    50 m/min saturate, less with the impulse.
    """
    rows = []
    for ankle in (True, False):
        for impulse in (True, False):
            points: list[tuple[SpeedMode, float]] = [("fixed", float(v)) for v in speeds_m_min]
            if free:
                points.append(("free", math.sqrt(150.0)))
            for mode, v in points:
                amplitude = (40.0 + 3.2 * v) * (0.6 if impulse else 1.0)
                gait = synthetic_gait(speed=v / 60.0, step_length=synthetic_step_length(v),
                                      ankle=ankle, impulse=impulse, torque_amplitude=amplitude,
                                      n_samples=n_samples)
                gait = dataclasses.replace(gait, cost={
                    "value": synthetic_cost(v, ankle=ankle, impulse=impulse),
                    "formula": "synthetic"})
                rel = gait_relpath(ankle=ankle, impulse=impulse, speed_mode=mode,
                                   speed_m_s=v / 60.0)
                if gaits:
                    gait.save(folder / rel)
                rows.append(summary_row(gait, ankle=ankle, impulse=impulse,
                                        speed_mode=mode, file=rel))
    write_summary(folder / SUMMARY_FILE, rows)
    return rows
