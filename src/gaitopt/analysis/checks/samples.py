"""Checks of the dense samples and of the constraints between knots.

A sample at time t belongs to the first phase whose last knot time is >= t, compared exactly
(a sample at a heel strike holds the pre-impact velocity: it belongs to the phase that ends
there; one a rounding error after it belongs to the next phase).

* ``samples.states``: the sample's ``(q, qd)`` equal the full state
  (:func:`.knots.full_state_function`) of the phase's state interpolant at t (the file's
  ``interpolation.states``: ``cubic_hermite`` through ``x`` with slopes ``xdot``; on a
  trapezoidal grid it equals the transcription's quadratic, whose end points and slopes are
  the same);
* ``samples.controls``: the sample's ``u`` equals the phase's piecewise-linear controls at t;
* ``samples.points``: each named point equals the forward kinematics of the sample's ``q``
  (``hip``: the base origin; ``knee_i``: the origin of leg i's shank; ``tip_i``: leg i's
  contact point; ``torso_top``: the base link's far end; leg 1 stands in the step);
* ``samples.normal_force``: normal forces recomputed from the sample's ``q, qd, u`` with the
  phase's contacts held, negative part (between knots a coarse grid may dip a little);
* ``bounds.*``: torques (samples) and joint limits (knots; samples, where the interpolant may
  overshoot a little); ``swing.clearance``: the swing tip's lowest point in single support.
"""

from __future__ import annotations

import functools

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.checks.check import Check, Worst
from gaitopt.analysis.checks.knots import full_state_function
from gaitopt.dynamics.functions import contact_dynamics_function
from gaitopt.dynamics.kinematics import contact_position, point_position
from gaitopt.gait.gait_file import Gait, phase_controls_at, phase_states_at
from gaitopt.robot.biped import biped_structure
from gaitopt.robot.model import RobotModel

Array = NDArray[np.float64]


def phase_of_samples(gait: Gait) -> list[NDArray[np.bool_]]:
    """One mask over ``gait.samples.t`` per phase (see the module docstring)."""
    t = gait.samples.t
    masks, taken = [], np.zeros(t.size, dtype=bool)
    for ph in gait.phases:
        mask = (t <= ph.t[-1]) & ~taken  # exact: a sample a rounding error later is not
        masks.append(mask)
        taken |= mask
    return masks


@functools.lru_cache(maxsize=16)
def points_function(model: RobotModel, names: tuple[str, ...]) -> ca.Function:
    """``q -> (2, len(names))`` world positions of the named sample points (see the module)."""
    legs = dict(zip(("_1", "_2"), biped_structure(model).legs, strict=True))  # leg 1, leg 2
    q = ca.SX.sym("q", model.nq)
    cols = []
    for name in names:
        if name == "hip":
            cols.append(point_position(model, q, model.base.name, (0.0, 0.0)))
        elif name == "torso_top":
            base = model.base
            cols.append(point_position(model, q, base.name, base.local_point(base.length)))
        elif name.startswith("knee") and name[-2:] in legs:
            cols.append(point_position(model, q, legs[name[-2:]].shank, (0.0, 0.0)))
        else:
            cols.append(contact_position(model, q, legs[name[-2:]].contact))
    return ca.Function("verify_points", [q], [ca.horzcat(*cols)])


def _known_points(gait: Gait) -> tuple[str, ...]:
    """The sample points this check knows (others are allowed and not checked)."""
    return tuple(n for n in gait.samples.points
                 if n in ("hip", "torso_top") or (n[-2:] in ("_1", "_2") and
                                                  n[:-2] in ("knee", "tip")))


def sample_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    """``samples.*``, ``bounds.*`` and ``swing.clearance`` (see the module docstring)."""
    model = gait.model
    s = gait.samples
    states, controls, force = Worst(), Worst(), Worst()
    for i, (ph, mask) in enumerate(zip(gait.phases, phase_of_samples(gait), strict=True)):
        if not mask.any():
            continue
        t, idx = s.t[mask], np.flatnonzero(mask)
        n = int(mask.sum())

        def at(k: int, i: int = i, t: Array = t, idx: NDArray[np.intp] = idx) -> str:
            return f"samples {idx[k]} (t = {t[k]:.4f} s, phases[{i}])"

        full = full_state_function(model, tuple(ph.state_names)).map(n)(
            phase_states_at(ph, t).T, gait.parameters["step_length"])
        q, qd = (np.asarray(v, dtype=float).T for v in full)
        err = np.max(np.abs(np.hstack([q - s.q[mask], qd - s.qd[mask]])), axis=1)
        err = np.where(np.isfinite(err), err, np.inf)  # out of the legs' reach
        k = int(np.argmax(err))
        states = states.update(err[k], at(k))
        err = np.max(np.abs(s.u[mask] - phase_controls_at(ph, t)), axis=1)
        k = int(np.argmax(err))
        controls = controls.update(err[k], at(k))
        dyn = contact_dynamics_function(model, ph.contacts, inputs="u")
        forces = np.asarray(dyn.map(n)(s.q[mask].T, s.qd[mask].T, s.u[mask].T)[1], dtype=float)
        if forces.size:
            normal = forces[1::2, :].min(axis=0)
            k = int(np.argmin(normal))
            force = force.update(-normal[k], at(k))
    names = _known_points(gait)
    pts = np.asarray(points_function(model, names).map(s.t.size)(s.q.T), dtype=float)
    pts = pts.reshape(2, s.t.size, len(names))  # (xy, sample, point): block k of P columns
    points = Worst()
    for j, name in enumerate(names):
        err = np.max(np.abs(pts[:, :, j].T - s.points[name]), axis=1)
        k = int(np.argmax(err))
        points = points.update(err[k], f"samples.points.{name} sample {k}")
    weight = model.total_mass * float(np.hypot(*model.gravity))
    return [states.check("samples.states", lim), controls.check("samples.controls", lim),
            points.check("samples.points", lim),
            Check("samples.normal_force", max(0.0, force.value),
                  lim["samples.normal_force"] * weight, force.where),
            *_bound_checks(gait, lim)]


def _bound_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    model = gait.model
    s = gait.samples
    torque, knots, between = Worst(), Worst(), Worst()
    for j, a in enumerate(model.actuators):
        lo, hi = a.limits
        excess = np.maximum(s.u[:, j] - hi, lo - s.u[:, j])
        k = int(np.argmax(excess))
        torque = torque.update(excess[k], f"{a.name} sample {k}")
    for joint in model.joints:
        c = model.joint_coordinate(joint.name)
        lo, hi = joint.limits
        for i, ph in enumerate(gait.phases):
            excess = np.maximum(ph.q[:, c] - hi, lo - ph.q[:, c])
            k = int(np.argmax(excess))
            knots = knots.update(excess[k], f"{joint.name} phases[{i}] knot {k}")
        excess = np.maximum(s.q[:, c] - hi, lo - s.q[:, c])
        k = int(np.argmax(excess))
        between = between.update(excess[k], f"{joint.name} sample {k}")
    t1 = gait.parameters["single_support_time"]
    swing = s.points["tip_2"][s.t <= s.t[0] + t1 + 1e-12, 1]  # leg 2 swings in phase 1
    k = int(np.argmin(swing))
    return [Check("bounds.torque", max(0.0, torque.value), lim["bounds.torque"], torque.where),
            Check("bounds.joints_knots", max(0.0, knots.value), lim["bounds.joints_knots"],
                  knots.where),
            Check("bounds.joints_samples", max(0.0, between.value),
                  lim["bounds.joints_samples"], between.where),
            Check("swing.clearance", max(0.0, -float(swing[k])), lim["swing.clearance"],
                  f"sample {k}")]
