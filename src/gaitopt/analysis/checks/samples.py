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
  (:func:`gaitopt.gait.record.sample_points`: ``hip``, the base origin; a joint's name, the
  origin of the link it moves; a contact's name, that point; ``torso_top``, the base link's
  far end);
* ``samples.normal_force``: normal forces recomputed from the sample's ``q, qd, u`` with the
  phase's contacts held, negative part (between knots a coarse grid may dip a little);
* ``bounds.*``: torques (samples) and joint limits (knots; samples, where the interpolant may
  overshoot a little); ``swing.clearance``: the lowest point of every contact point while it
  is not held (the swing tip in single support), its depth below the ground.
"""

from __future__ import annotations

import functools

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.checks.check import Check, Worst
from gaitopt.analysis.checks.knots import full_state_function
from gaitopt.dynamics.functions import contact_dynamics_function
from gaitopt.dynamics.kinematics import point_position
from gaitopt.gait.contact_sequence import phase_holds
from gaitopt.gait.full_physics import hold_axes
from gaitopt.gait.gait_file import Gait
from gaitopt.gait.interpolation import phase_controls_at, phase_states_at
from gaitopt.gait.record_points import point_names, sample_points
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
    """``q -> (2, len(names))`` world positions of the named sample points
    (:func:`gaitopt.gait.record.sample_points`)."""
    where = {name: (link, p) for name, link, p in sample_points(model)}
    q = ca.SX.sym("q", model.nq)
    cols = [point_position(model, q, *where[name]) for name in names]
    return ca.Function("verify_points", [q], [ca.horzcat(*cols)])


def _known_points(gait: Gait) -> tuple[str, ...]:
    """The sample points this check knows (others are allowed and not checked)."""
    known = set(point_names(gait.model))
    return tuple(n for n in gait.samples.points if n in known)


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
        holds = phase_holds(gait.contact_sequence, i, ph.contacts)
        dyn = contact_dynamics_function(model, holds, inputs="u")
        forces = np.asarray(dyn.map(n)(s.q[mask].T, s.qd[mask].T, s.u[mask].T)[1], dtype=float)
        if forces.size:
            normal_rows = [r for r, (_, axis) in enumerate(hold_axes(holds)) if axis == 1]
            normal = forces[normal_rows, :].min(axis=0)
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
        excess = np.maximum(np.maximum(s.u[:, j] - hi, lo - s.u[:, j]), 0.0)  # unbounded: 0
        k = int(np.argmax(excess))
        torque = torque.update(excess[k], f"{a.name} sample {k}")
    for joint in model.joints:
        c = model.joint_coordinate(joint.name)
        lo, hi = joint.limits
        for i, ph in enumerate(gait.phases):
            excess = np.maximum(np.maximum(ph.q[:, c] - hi, lo - ph.q[:, c]), 0.0)
            k = int(np.argmax(excess))
            knots = knots.update(excess[k], f"{joint.name} phases[{i}] knot {k}")
        excess = np.maximum(np.maximum(s.q[:, c] - hi, lo - s.q[:, c]), 0.0)
        k = int(np.argmax(excess))
        between = between.update(excess[k], f"{joint.name} sample {k}")
    lowest = Worst(-np.inf)
    contacts = [point.name for point in model.contacts]
    for i, (ph, mask) in enumerate(zip(gait.phases, phase_of_samples(gait), strict=True)):
        for name in contacts:
            if name in ph.contacts or name not in s.points or not mask.any():
                continue
            heights = s.points[name][mask, 1]
            k = int(np.argmin(heights))
            lowest = lowest.update(-float(heights[k]),
                                   f"{name} sample {int(np.flatnonzero(mask)[k])} (phases[{i}])")
    return [Check("bounds.torque", max(0.0, torque.value), lim["bounds.torque"], torque.where),
            Check("bounds.joints_knots", max(0.0, knots.value), lim["bounds.joints_knots"],
                  knots.where),
            Check("bounds.joints_samples", max(0.0, between.value),
                  lim["bounds.joints_samples"], between.where),
            Check("swing.clearance", max(0.0, lowest.value), lim["swing.clearance"],
                  lowest.where)]
