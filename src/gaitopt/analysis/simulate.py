"""Replaying a gait in MuJoCo, step after step, with PD tracking (``gaitopt simulate``;
``docs/simulate.md``).

The robot starts at the gait's initial state (``q``, ``qd`` of the first knot). Each step
replays the gait's phases in order, as the return map of :mod:`.stability` does: a phase that
ends at a touchdown (the gait's ``heel_strike``, the heel-toe walk's ``foot_flat``) ends when
that point's contact geom touches the ground while it is at least ``arm_distance`` (half a step
length) ahead of where the step's stance point stood at the step's start; every other phase
lasts its recorded duration. A swing point passes through the ground until the phase that ends
with its touchdown has begun and it is armed (``ghost_swing``, the default: the return map's
hybrid model, in which a point meets the ground only at its touchdown; optimal gaits graze the
ground in mid-swing, where their clearance constraint is active, at the knots only: the
seven-link walk at 60 m/min dips its swing toe 1.6 mm into the ground 0.46 m ahead of the
origin, which a solid ground turns into a trip; ``ghost_swing=False`` makes every point solid
all the time). The next step is the same motion with the legs swapped
(:func:`gaitopt.robot.symmetry.leg_swap`: ``S_q q``, ``S_u u``, contacts renamed) and
its origin at the new stance point's measured position.

Within a phase the reference is the gait file's own interpolation
(:mod:`gaitopt.gait.record.interpolation`: states cubic Hermite, mapped to ``q``, ``qd``; torques
piecewise linear), tabulated every :data:`TABLE_STEP` s and read linearly in between, indexed

* ``tracking="time"``: by the phase's own clock from its start (the last value held if the
  phase runs longer), the return map's controller, or
* ``tracking="phase"``: in the phases that end at a touchdown (the swing), by a monotonic
  phase variable, the hip's forward position relative to the step's origin,
  ``theta = x_hip - x_origin``: the reference at ``tau(theta)``, the inverse of the gait's
  ``theta(tau)`` (clipped to the phase), velocities scaled by the measured
  ``theta_dot / theta_dot_ref(tau)``; the phases of fixed duration (double support, foot
  flat) keep their clocks (indexed by the hip, a double support whose hip stalls never ends:
  the five-link walk without ankle torques rolls back and stops).

Torques: ``u = u_ff + kp B^T (q_ref - q) + kd B^T (qd_ref - qd)`` (N m; ``B`` the actuation
matrix: a joint actuator tracks its joint, a contact actuator (the five-link model's ankles)
its link's absolute angle). Joint actuators are MuJoCo servos with an affine bias (the damping
integrated implicitly), their total torque clipped to the model's bounds; a contact actuator
is an external torque on its link (``xfrc_applied``) applied only while its contact geom
touches the ground, clipped to its bounds as well.

The robot has **fallen** when the hip (the base origin) is below :data:`HIP_FRACTION` of its
standing height, the base link's angle leaves +-:data:`BASE_ANGLE_LIMIT` rad, a body origin
(a joint: hip, knee, ankle) is below the ground, or a step does not end within three nominal
step times (the robot stopped).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.checks.knots import full_state_function
from gaitopt.analysis.mujoco_model import MujocoRobot, import_mujoco, mujoco_robot
from gaitopt.analysis.stability import step_from_gait
from gaitopt.dynamics.actuation import actuation_rows
from gaitopt.dynamics.kinematics import contact_position
from gaitopt.gait.record.file import Gait, GaitPhase
from gaitopt.gait.record.interpolation import phase_controls_at, phase_states_at
from gaitopt.robot.mjcf_export import MjcfContact
from gaitopt.robot.model import BASE_ANGLE, BASE_X, BASE_Y, RobotModel
from gaitopt.robot.symmetry import leg_swap

Array = NDArray[np.float64]
Tracking = Literal["time", "phase"]

#: Spacing (s) of the tabulated reference (linear in between: errors of order 1e-6 rad).
TABLE_STEP = 2.5e-4
#: Fall: hip below this fraction of its standing height (all joints at 0, on its lowest point).
HIP_FRACTION = 0.5
#: Fall: the base link's angle beyond +- this (rad).
BASE_ANGLE_LIMIT = 1.0
#: Without a geom of its name (``--mjcf FILE``), a point touches the ground at this height (m).
TOUCH_HEIGHT = 1e-3
#: The trajectory is recorded every this many s (100 Hz).
RECORD_STEP = 0.01
#: A step that lasts this many nominal step times has stopped (a fall).
STALL_FACTOR = 3.0


class SimulationError(ValueError):
    """The gait cannot be simulated (bad options, a reference that cannot be indexed)."""


@dataclass(frozen=True, eq=False)
class _PhaseTable:
    """A phase's reference on a dense grid of the step clock: ``tau`` (M,), ``q``, ``qd``
    (M, nq), ``u`` (M, nu)."""

    tau: Array
    q: Array
    qd: Array
    u: Array

    def at(self, tau: float) -> tuple[Array, Array, Array]:
        k = int(np.clip(np.searchsorted(self.tau, tau) - 1, 0, self.tau.size - 2))
        s = float(np.clip((tau - self.tau[k]) / (self.tau[k + 1] - self.tau[k]), 0.0, 1.0))
        q, qd, u = ((1 - s) * a[k] + s * a[k + 1] for a in (self.q, self.qd, self.u))
        return q, qd, u


def _table(model: RobotModel, phase: GaitPhase, step_length: float) -> _PhaseTable:
    """The gait file's interpolation of ``phase`` every :data:`TABLE_STEP` s or finer."""
    n = max(int(np.ceil(phase.duration / TABLE_STEP)) + 1, 2)
    tau = np.linspace(phase.t[0], phase.t[-1], n)
    x = phase_states_at(phase, tau)
    f = full_state_function(model, tuple(phase.state_names)).map(n)
    q, qd = (np.asarray(v, dtype=float).T for v in f(x.T, step_length))
    return _PhaseTable(tau, q, qd, phase_controls_at(phase, tau))


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """What a simulation did. ``steps`` walked (completed) of ``steps_asked``; ``fell`` and
    ``fall_reason`` (None if it did not fall); ``time`` (s) and ``distance`` (m, the hip's) of
    the completed steps and their ``speed`` (m/s) against the gait's ``gait_speed``;
    tracking errors of the joint angles over the whole run (rad): ``rms_error``,
    ``max_error``; per completed step its duration ``step_times`` (s) and length
    ``step_lengths`` (m, between successive stance points); ``peak_torque_ratio``: the largest
    |torque| / bound; ``t`` (N,) and ``q`` (N, nq) the simulated trajectory at 100 Hz
    (physical leg labels), ``qpos`` (N, nq) MuJoCo's, ``robot`` the MuJoCo model;
    ``settings``: gains, tracking, contact parameters, the MJCF's source."""

    steps: int
    steps_asked: int
    fell: bool
    fall_reason: str | None
    time: float
    distance: float
    speed: float
    gait_speed: float
    rms_error: float
    max_error: float
    step_times: tuple[float, ...]
    step_lengths: tuple[float, ...]
    peak_torque_ratio: float
    t: Array
    q: Array
    qpos: Array
    robot: MujocoRobot
    settings: dict[str, Any] = field(default_factory=dict)


def standing_height(model: RobotModel) -> float:
    """Height (m) of the base origin above the lowest contact point with every joint and the
    base angle at 0."""
    q = np.zeros(model.nq)
    low = min(float(np.asarray(contact_position(model, q, c.name), float).ravel()[1])
              for c in model.contacts)
    return -low


def simulate_gait(gait: Gait, *, steps: int = 10, pd: tuple[float, float] = (1000.0, 60.0),
                  tracking: Tracking = "time", contact: MjcfContact | None = None,
                  mjcf: str | None = None, bounded: bool = True, ghost_swing: bool = True,
                  progress: Callable[[str], None] | None = None) -> SimulationResult:
    """Simulate ``steps`` steps of ``gait`` in MuJoCo (module docstring) with PD gains
    ``pd = (kp, kd)`` (N m/rad, N m s/rad); ``mjcf`` a file matched to the model by name
    instead of the export; ``bounded`` clips every torque to its actuator's bounds;
    ``ghost_swing``: a step's swing point (one whose touchdown ends a phase) collides with
    the ground only from the start of that phase and once it is ``arm_distance`` ahead of
    the step's origin (module docstring); ``progress`` gets a line per step."""
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise SimulationError(f"steps: got {steps!r}; allowed: an integer >= 1")
    if len(pd) != 2 or not all(np.isfinite(pd)) or min(pd) < 0:
        raise SimulationError(f"pd: got {pd!r}; allowed: two finite gains kp, kd >= 0")
    if tracking not in ("time", "phase"):
        raise SimulationError(f"tracking: got {tracking!r}; allowed: 'time' or 'phase'")
    contact = contact or MjcfContact(friction=float(gait.options.get("friction") or 1.0))
    mujoco = import_mujoco()
    model = gait.model
    spec = step_from_gait(gait)  # the step's structure: phases, guards, stance point
    robot = mujoco_robot(model, contact=contact, mjcf=mjcf)
    kp, kd = (float(g) for g in pd)
    robot.set_servos(kp, kd, bounded=bounded)
    mj, cmap = robot.mj, robot.coordinates
    data = mujoco.MjData(mj)
    swap = leg_swap(model)
    s_q, s_u = swap.s_q, swap.s_u  # the swap's linear maps of q (and qd) and of u
    tables = [_table(model, ph, gait.step_length) for ph in gait.phases]
    # theta(tau) of the whole step: the hip's x relative to the origin (the phases' shared
    # boundary samples once)
    theta_ref = np.concatenate([tb.q[int(i > 0):, BASE_X] for i, tb in enumerate(tables)])
    tau_ref = np.concatenate([tb.tau[int(i > 0):] for i, tb in enumerate(tables)])
    if tracking == "phase" and np.any(np.diff(theta_ref) <= 0):
        raise SimulationError("tracking='phase': the gait's hip does not move forward "
                              "monotonically, so its forward position cannot index the step")
    joints = np.array([model.joint_coordinate(j.name) for j in model.joints])
    ground_torques = [(j, a.contact or "", np.flatnonzero(np.array(
        actuation_rows(model, [a.contact or ""]))[:, j])) for j, a in enumerate(model.actuators)
        if a.contact is not None]
    link_body = robot.contact_bodies
    bounds = np.array([a.limits for a in model.actuators], dtype=float).reshape(-1, 2)
    hip_min = HIP_FRACTION * standing_height(model)

    cmap.set_state(data, gait.phases[0].q[0], gait.phases[0].qd[0])
    mujoco.mj_forward(mj, data)

    def touching(point: str) -> bool:
        if point not in robot.contact_geoms:  # a file without the point's geom: its height
            return point_xy(point)[1] <= TOUCH_HEIGHT
        g = robot.contact_geoms[point]
        for k in range(data.ncon):
            con = data.contact[k]
            if (con.geom1 == g and con.geom2 in robot.ground_geoms) or (
                    con.geom2 == g and con.geom1 in robot.ground_geoms):
                return True
        return False

    def point_xy(point: str) -> Array:
        if point in robot.contact_geoms:
            return np.asarray(data.geom_xpos[robot.contact_geoms[point]])[[0, 2]]
        q_now = cmap.q(data.qpos)
        return np.asarray(contact_position(model, q_now, point), dtype=float).ravel()

    def point_x(point: str) -> float:
        return float(point_xy(point)[0])

    step, phase, t_phase0 = 0, 0, 0.0
    names = dict(swap.contacts)
    label = dict.fromkeys(names, "")  # gait label -> physical label, set per step

    def relabel(k: int) -> None:
        for c in names:
            label[c] = names[c] if k % 2 else c

    guard_points: dict[str, int] = {}  # swing point -> the phase its touchdown ends
    for i in spec.guard_phases:
        guard_points.setdefault(spec.guard_point(i), i)
    filters = {g: (int(mj.geom_contype[g]), int(mj.geom_conaffinity[g]))
               for g in robot.contact_geoms.values()}

    def collide(point: str, on: bool) -> None:
        if point not in robot.contact_geoms:
            return  # a file's own feet stay solid
        g = robot.contact_geoms[point]
        mj.geom_contype[g], mj.geom_conaffinity[g] = filters[g] if on else (0, 0)

    def disarm() -> None:  # the step's swing points pass through the ground until armed
        for c in robot.contact_geoms:
            collide(c, True)
        if ghost_swing:
            for c in guard_points:
                collide(label[c], False)

    relabel(0)
    origin = point_x(label[spec.stance])
    disarm()
    step_start_t, step_start_origin = 0.0, origin
    step_times: list[float] = []
    step_lengths: list[float] = []
    sq_err, n_err, max_err, peak = 0.0, 0, 0.0, 0.0
    rec_t: list[float] = []
    rec_q: list[Array] = []
    rec_qpos: list[Array] = []
    fall: str | None = None
    dt = float(mj.opt.timestep)
    record_every = max(1, round(RECORD_STEP / dt))
    nominal = gait.step_time
    while step < steps:
        t = float(data.time)
        q, qd = cmap.q(data.qpos), cmap.qd(data.qvel)
        q_g = s_q @ q if step % 2 else q  # gait labels (S_q is an involution)
        qd_g = s_q @ qd if step % 2 else qd
        table = tables[phase]
        ph = gait.phases[phase]
        by_clock = tracking == "time" or spec.phases[phase].duration is not None
        if by_clock:
            tau = ph.t[0] + min(t - t_phase0, ph.duration)
            q_r, qd_r, u_r = table.at(tau)
        else:
            theta = q_g[BASE_X] - origin
            tau = float(np.interp(theta, theta_ref, tau_ref))
            tau = float(np.clip(tau, ph.t[0], ph.t[-1]))
            q_r, qd_r, u_r = table.at(tau)
            k = int(np.clip(np.searchsorted(table.tau, tau) - 1, 0, table.tau.size - 2))
            rate_ref = (table.q[k + 1, BASE_X] - table.q[k, BASE_X]) / (
                table.tau[k + 1] - table.tau[k])
            qd_r = qd_r * (qd_g[BASE_X] / rate_ref)
        err = np.abs(q_g[joints] - q_r[joints])
        sq_err += float(err @ err)
        n_err += err.size
        max_err = max(max_err, float(err.max()))
        if ghost_swing:
            for c, first in guard_points.items():
                if phase >= first and point_x(label[c]) - origin >= spec.arm_distance:
                    collide(label[c], True)
        # phase end
        guard = spec.guard_point(phase) if spec.phases[phase].duration is None else None
        if guard is not None:
            point = label[guard]
            done = touching(point) and point_x(point) - origin >= spec.arm_distance
        else:
            done = t - t_phase0 >= ph.duration - 0.5 * dt
        if done:
            phase, t_phase0 = phase + 1, t
            if phase == len(gait.phases):
                step, phase = step + 1, 0
                relabel(step)
                new_origin = point_x(label[spec.stance])
                step_times.append(t - step_start_t)
                step_lengths.append(new_origin - step_start_origin)
                step_start_t, step_start_origin = t, new_origin
                origin = new_origin
                disarm()
                if progress is not None:
                    progress(f"step {step}/{steps}: {step_times[-1]:.3f} s, length "
                             f"{step_lengths[-1]:.3f} m, hip at x = {q[BASE_X]:.3f} m")
                if step == steps:
                    break
            continue
        # torques in physical labels
        u_ff = s_u @ u_r if step % 2 else u_r
        q_ref = s_q @ q_r if step % 2 else q_r
        qd_ref = s_q @ qd_r if step % 2 else qd_r
        data.ctrl[:] = robot.servo_ctrl(u_ff, q_ref, qd_ref, kp, kd)
        data.xfrc_applied[:] = 0.0
        for j, point, chain in ground_torques:
            if not touching(point):
                continue
            tau_j = (u_ff[j] + kp * float(np.sum(q_ref[chain] - q[chain]))
                     + kd * float(np.sum(qd_ref[chain] - qd[chain])))
            if bounded:
                tau_j = float(np.clip(tau_j, *bounds[j]))
            peak = max(peak, abs(tau_j) / max(abs(bounds[j]).max(), 1e-12))
            data.xfrc_applied[link_body[point], 4] = -tau_j  # +tau about gaitopt z = -y
        if round(t / dt) % record_every == 0:
            rec_t.append(t)
            rec_q.append(q)
            rec_qpos.append(np.array(data.qpos))
        mujoco.mj_step(mj, data)
        for j, (act, g) in robot.joint_actuators.items():
            peak = max(peak, abs(float(data.actuator_force[act]) * g)
                       / max(abs(bounds[j]).max(), 1e-12))
        # falls
        q = cmap.q(data.qpos)
        if q[BASE_Y] < hip_min:
            fall = f"the hip fell below {hip_min:.3f} m ({HIP_FRACTION:g} x standing height)"
        elif abs(q[BASE_ANGLE]) > BASE_ANGLE_LIMIT:
            fall = (f"the {model.base.name} turned beyond +-{BASE_ANGLE_LIMIT:g} rad "
                    f"({q[BASE_ANGLE]:.2f} rad)")
        elif np.any(data.xpos[1:, 2] < 0.0):
            body = int(np.argmin(data.xpos[1:, 2])) + 1
            fall = f"body {mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, body)!r} hit the ground"
        elif data.time - step_start_t > STALL_FACTOR * nominal:
            fall = (f"step {step + 1} did not end within {STALL_FACTOR:g} nominal step times "
                    "(the robot stopped)")
        if fall is not None:
            fall = f"fell in step {step + 1} at t = {data.time:.3f} s: {fall}"
            if progress is not None:
                progress(fall)
            break
    t_done = float(sum(step_times))
    distance = float(sum(step_lengths))  # between the first and the last stance points
    return SimulationResult(
        steps=step, steps_asked=steps, fell=fall is not None, fall_reason=fall, time=t_done,
        distance=distance, speed=distance / t_done if t_done > 0 else 0.0,
        gait_speed=gait.speed, rms_error=float(np.sqrt(sq_err / max(n_err, 1))),
        max_error=max_err, step_times=tuple(step_times), step_lengths=tuple(step_lengths),
        peak_torque_ratio=peak, t=np.array(rec_t), q=np.array(rec_q).reshape(-1, model.nq),
        qpos=np.array(rec_qpos).reshape(-1, mj.nq), robot=robot,
        settings={"pd": [kp, kd], "tracking": tracking, "torques_bounded": bounded,
                  "contact": contact.describe(), "mjcf": robot.source,
                  "ghost_swing": ghost_swing,
                  "fall_criteria": f"hip below {HIP_FRACTION:g} x standing height "
                  f"({hip_min:.3f} m), |{model.base.name}| > {BASE_ANGLE_LIMIT:g} rad, a body "
                  f"origin below the ground, a step longer than {STALL_FACTOR:g} x "
                  f"{nominal:.3f} s"})
