"""A naive initial guess for the walking problem, built from geometry alone.

No guess files: for any speed ``v`` and step length ``L`` the guess is

* the hip moving forward at constant speed ``v`` at a constant height chosen so that both
  legs reach the ground with ``r <= r_max`` throughout (centred so that double support is
  symmetric about the middle of the two tips), the torso upright;
* the swing tip travelling from ``(-L, 0)`` to ``(L, 0)`` on a smooth arc (smoothstep in x,
  a half sine of height ``clearance`` in y), the swing leg from inverse kinematics;
* rates and accelerations by differentiating these curves;
* the torques that realise this motion with the least ``u'u``: at each knot the least-squares
  solution of ``M qdd + h = B u + J^T f`` over torques ``u`` and contact forces ``f``
  (forces weighted lightly so the torques are what is minimised).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from gaitopt.dynamics.actuation import actuation_matrix
from gaitopt.dynamics.crba import crba
from gaitopt.dynamics.kinematics import contact_jacobian
from gaitopt.dynamics.reduced import leg_inverse_kinematics
from gaitopt.dynamics.rnea import bias_forces
from gaitopt.gait import walking
from gaitopt.gait.full_physics import actuator_names
from gaitopt.gait.full_physics import state_names as full_state_names
from gaitopt.gait.model_scale import REFERENCE, ModelScale, model_scale
from gaitopt.gait.walking import DOUBLE, SINGLE
from gaitopt.ocp import Guess as OcpGuess
from gaitopt.ocp import PhaseGuess as OcpPhaseGuess
from gaitopt.robot.biped import biped_of, reduced_biped
from gaitopt.robot.model import BASE_POSITION, RobotModel

Array = NDArray[np.float64]

#: Samples per phase used to differentiate the guess curves.
_FINE = 400
#: Weight (1/m on the reference biped's 1 m legs) of the contact forces' columns in the
#: least-squares torques of the guess (:func:`_torques`): forces are cheap.
FORCE_WEIGHT = 100.0


@dataclass(frozen=True)
class PhaseGuess:
    """Knot values of one phase: ``t`` (K,), ``x`` (K, n) named by ``states``, ``u`` (K, m)
    named by ``controls`` (the actuators acting in the phase)."""

    name: str
    t: Array
    x: Array
    u: Array
    states: tuple[str, ...]
    controls: tuple[str, ...]


@dataclass(frozen=True)
class WalkingGuess:
    phases: tuple[PhaseGuess, ...]
    parameters: dict[str, float]

    def to_ocp(self) -> OcpGuess:
        """The engine's guess object (values at normalised knot times)."""
        phases = {}
        for ph in self.phases:
            span = ph.t[-1] - ph.t[0]
            phases[ph.name] = OcpPhaseGuess(
                x={n: ph.x[:, j] for j, n in enumerate(ph.states)},
                u={n: ph.u[:, j] for j, n in enumerate(ph.controls)},
                tau=(ph.t - ph.t[0]) / span)
        return OcpGuess(phases=phases, parameters=dict(self.parameters))


def default_step_length(speed: float, scale: ModelScale = REFERENCE) -> float:
    """A plausible step length (m) for a speed (m/s) to start from: grows with speed. On the
    reference biped (legs of 1 m) ``clip(0.06 + 0.35 v, 0.05, 0.5)``; on another model the
    same at equal Froude number, ``l * L_ref(v_ref)`` with ``v_ref`` the reference biped's
    speed of that Froude number (``scale``: :func:`gaitopt.gait.model_scale.model_scale`)."""
    v_ref = scale.to_reference_speed(speed)
    return scale.length(float(np.clip(0.06 + 0.35 * v_ref, 0.05, 0.5)))


def smoothstep(s: Array) -> Array:
    """The cubic ``3 s^2 - 2 s^3``: 0 at ``s = 0``, 1 at ``s = 1``, flat at both ends."""
    return s * s * (3.0 - 2.0 * s)


def knot_times(t0: float, duration: float, count: int) -> Array:
    """``count`` uniform knot times (s) from ``t0`` over ``duration``, both ends included."""
    return t0 + duration * np.linspace(0.0, 1.0, count)


def _torques(model: RobotModel, q: Array, qd: Array, qdd: Array, controls: tuple[str, ...],
             held: list[str]) -> Array:
    """Least-``u'u`` torques (and any contact forces) realising ``qdd``: forces are cheap in
    the least-squares norm, their columns weighted by :data:`FORCE_WEIGHT` over the leg length
    ratio (torques scale as ``m g l``, forces as ``m g``)."""
    m_q = np.asarray(crba(model, q), dtype=float)
    h = np.asarray(bias_forces(model, q, qd), dtype=float).reshape(-1)
    b_full = np.asarray(actuation_matrix(model, q, held), dtype=float)
    cols = [model.actuator_index(n) for n in controls]
    force_scale = FORCE_WEIGHT / model_scale(model).length_factor
    a = b_full[:, cols]
    if held:
        j = np.asarray(contact_jacobian(model, q, held), dtype=float).reshape(-1, model.nq)
        a = np.hstack([a, force_scale * j.T])
    sol, *_ = np.linalg.lstsq(a, m_q @ qdd + h, rcond=None)
    return np.asarray(sol[: len(cols)], dtype=float)


def naive_guess(model: RobotModel, *, speed: float, step_length: float,
                single_support_fraction: float, knots: tuple[int, int], ankle: bool,
                r_max: float, clearance: float | None = None,
                ankle_torques: bool | None = None, full: bool = False) -> WalkingGuess:
    """The geometric guess described in the module docstring (knot values per phase).

    ``ankle`` says whether the controls include the ankle torques; ``ankle_torques`` (default:
    ``ankle``) whether the least-squares torques may use them (``False``: they are zero, the
    guess of a stage that holds the ankles at zero). ``full``: the states are ``[q, qd]``
    (the full-coordinate formulation; joints other than the legs' stay at 0), else the reduced
    states of :mod:`gaitopt.gait.walking`."""
    use_ankles = ankle if ankle_torques is None else ankle_torques and ankle
    stance, swing = (biped_of(model) if full else reduced_biped(model)).legs
    v, step, f = speed, step_length, single_support_fraction
    total = step / v
    t1, t2 = f * total, (1.0 - f) * total
    offset = step * (1.0 - f / 2.0)
    height = 0.995 * float(np.sqrt(max(r_max**2 - offset**2, 1e-4)))
    # The swing tip's arc: on the reference biped (1 m legs) min(0.04, 0.01 + 0.1 L) m.
    scale = model_scale(model)
    lift = (clearance if clearance is not None else
            scale.length(min(0.04, 0.01 + 0.1 * step / scale.length_factor)))

    def hip(t: Array) -> Array:
        return np.stack([-step * f / 2.0 + v * t, np.full_like(t, height)], axis=1)

    phases = []
    # Phase 1: single support on leg 1, swing leg 2 along an arc.
    t_fine = np.linspace(0.0, t1, _FINE)
    s = t_fine / t1
    tip2 = np.stack([-step + 2.0 * step * smoothstep(s), lift * np.sin(np.pi * s)], axis=1)
    p_hip = hip(t_fine)
    q_fine = np.zeros((_FINE, model.nq))
    q_fine[:, BASE_POSITION] = p_hip
    for k in range(_FINE):
        for leg, tip in ((stance, (0.0, 0.0)), (swing, tuple(tip2[k]))):
            joints = leg_inverse_kinematics(leg, list(p_hip[k]), [0.0, 0.0], list(tip), 0.0,
                                            0.0)
            q_fine[k, leg.hip_index] = float(joints.hip)
            q_fine[k, leg.knee_index] = float(joints.knee)
    phases.append(phase_guess(model, SINGLE, t_fine, q_fine, knot_times(0.0, t1, knots[0]),
                              ankle, use_ankles, [stance.contact], full))
    if f < 1.0:
        t_fine = np.linspace(t1, t1 + t2, _FINE)
        p_hip = hip(t_fine)
        q_fine = np.zeros((_FINE, model.nq))
        q_fine[:, BASE_POSITION] = p_hip
        for k in range(_FINE):
            for leg, tip in ((stance, (0.0, 0.0)), (swing, (step, 0.0))):
                joints = leg_inverse_kinematics(leg, list(p_hip[k]), [0.0, 0.0], list(tip),
                                                0.0, 0.0)
                q_fine[k, leg.hip_index] = float(joints.hip)
                q_fine[k, leg.knee_index] = float(joints.knee)
        phases.append(phase_guess(model, DOUBLE, t_fine, q_fine,
                                  knot_times(t1, t2, knots[1]), ankle, use_ankles,
                                  [stance.contact, swing.contact], full))
    return WalkingGuess(phases=tuple(phases),
                        parameters={"step_length": step, "speed": v, "impulse": 0.0})


def default_running_step(speed: float, scale: ModelScale = REFERENCE) -> float:
    """A plausible running step length (m) for a speed (m/s) to start from: on the reference
    biped ``clip(0.35 v, 0.3, 1.2)``, on another model at equal Froude number (as
    :func:`default_step_length`)."""
    v_ref = scale.to_reference_speed(speed)
    return scale.length(float(np.clip(0.35 * v_ref, 0.3, 1.2)))


def naive_running_guess(model: RobotModel, *, speed: float, step_length: float,
                        stance_fraction: float, knots: tuple[int, int], ankle: bool,
                        r_max: float, ankle_torques: bool | None = None) -> WalkingGuess:
    """A geometric guess of a run in full coordinates (phases ``stance`` and ``flight``).

    The hip moves at constant speed at the height where the stance leg reaches its tip at the
    origin over the whole stance; tip 1 stands during the stance, then flies to ``(L + xb,
    yb)``; tip 2 travels over the whole step from ``(xb, yb)`` to its landing point ``(L, 0)``
    (``xb = -0.6 L``, ``yb = 0.1 m``: the swap of legs maps tip 1's end onto tip 2's start),
    both on smooth arcs; torques by least squares as for the walk."""
    use_ankles = ankle if ankle_torques is None else ankle_torques and ankle
    stance, swing = biped_of(model).legs
    v, step, f = speed, step_length, stance_fraction
    total = step / v
    t1 = f * total
    s_hip = v * t1
    height = 0.97 * float(np.sqrt(max(r_max**2 - (s_hip / 2.0) ** 2, 1e-4)))
    # Tip 2's start behind the hip and the arcs' heights (m on the reference biped's 1 m legs).
    xb, yb, bump = -0.6 * step, model_scale(model).length(0.1), model_scale(model).length(0.05)
    phases = []
    for name, (ta, tb), held in (("stance", (0.0, t1), [stance.contact]),
                                 ("flight", (t1, total), [])):
        t = np.linspace(ta, tb, _FINE)
        p_hip = np.stack([-s_hip / 2.0 + v * t, np.full_like(t, height)], axis=1)
        sig2 = smoothstep(t / total)
        tip2 = np.stack([xb + (step - xb) * sig2,
                         yb * (1.0 - sig2) + bump * np.sin(np.pi * t / total)], axis=1)
        if name == "stance":
            tip1 = np.zeros_like(tip2)
        else:
            sig1 = smoothstep((t - t1) / (total - t1))
            tip1 = np.stack([(step + xb) * sig1,
                             yb * sig1 + bump * np.sin(np.pi * (t - t1) / (total - t1))],
                            axis=1)
        q_fine = np.zeros((_FINE, model.nq))
        q_fine[:, BASE_POSITION] = p_hip
        for k in range(_FINE):
            for leg, tip in ((stance, tip1[k]), (swing, tip2[k])):
                joints = leg_inverse_kinematics(leg, list(p_hip[k]), [0.0, 0.0], list(tip),
                                                0.0, 0.0)
                q_fine[k, leg.hip_index] = float(joints.hip)
                q_fine[k, leg.knee_index] = float(joints.knee)
        count = knots[0] if name == "stance" else knots[1]
        phases.append(phase_guess(model, name, t, q_fine, knot_times(ta, tb - ta, count), ankle,
                                  use_ankles, held, True))
    return WalkingGuess(phases=tuple(phases),
                        parameters={"step_length": step, "speed": v, "impulse": 0.0})


def phase_guess(model: RobotModel, phase: str, t_fine: Array, q_fine: Array, t_knots: Array,
                ankle: bool, use_ankles: bool, held: list[str], full: bool) -> PhaseGuess:
    """The guess of one phase from a motion ``q_fine`` (rows at the times ``t_fine``): its
    states at ``t_knots`` (full ``[q, qd]`` if ``full``, else the phase's reduced states) and
    the least-squares torques that realise it with the ``held`` contact points on the ground
    (ankle torques only if ``use_ankles``; ``ankle`` says whether the phase has them)."""
    qd_fine = np.gradient(q_fine, t_fine, axis=0)
    qdd_fine = np.gradient(qd_fine, t_fine, axis=0)
    controls = actuator_names(model, held, ankle=ankle)
    acting = actuator_names(model, held, ankle=use_ankles)
    columns = [controls.index(name) for name in acting]
    xs, us = [], []
    for t in t_knots:
        q = np.array([np.interp(t, t_fine, q_fine[:, i]) for i in range(model.nq)])
        qd = np.array([np.interp(t, t_fine, qd_fine[:, i]) for i in range(model.nq)])
        qdd = np.array([np.interp(t, t_fine, qdd_fine[:, i]) for i in range(model.nq)])
        if full:
            x = np.concatenate([q, qd])
        elif phase == SINGLE:
            x = walking.full_to_single_support(model, q, qd)
        else:
            x = walking.full_to_double_support(model, q, qd)
        xs.append(np.asarray(x, dtype=float).reshape(-1))
        u = np.zeros(len(controls))
        u[columns] = _torques(model, q, qd, qdd, acting, held)
        us.append(u)
    states = full_state_names(model) if full else walking.state_names(model, phase)
    return PhaseGuess(name=phase, t=np.asarray(t_knots), x=np.array(xs), u=np.array(us),
                      states=states, controls=controls)
