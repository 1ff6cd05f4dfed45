"""A naive initial guess for any model and contact sequence, by numerical inverse kinematics.

The leg inverse kinematics of :mod:`gaitopt.gait.guess.naive` needs thigh-shank legs with point
tips. For any other tree (feet, knee-less legs, extra links) and any
:class:`~gaitopt.gait.sequence.contact_sequence.ContactSequence`, this guess asks only where the
contact points should be and solves for the configuration:

* every contact point gets a target over the step: where it is held (its anchor
  ``anchor L + offset``, ``y = 0``; only ``y = 0`` for a normal-only hold of a point without an
  anchor), and between two holds a smooth arc from the last ground point to the next
  (smoothstep in ``x``, a half sine of height ``lift`` in ``y``). The holds of neighbouring
  steps come through the leg swap: point ``c`` at time ``t + T`` is where point ``swap(c)``
  is at ``t``, one step length ahead (and ``c`` itself two steps ahead);
* the base moves forward at the speed ``v``, passing over the middle of the held points at
  mid-step, at about the standing height; the torso upright;
* at each of :data:`SAMPLES` times per phase ``q`` minimises (``scipy.optimize.least_squares``,
  within the joint limits, started from the previous sample) the weighted squared distance of
  the points to their targets (held points weigh more, and any point below the ground
  weighs as much) plus weak terms pulling the base to its path and the joints to
  a slightly flexed pose;
* rates, accelerations and least-squares torques as in :mod:`gaitopt.gait.guess.naive`.

A step the legs cannot reach (a held point more than :data:`PLACEMENT_TOL` from its ground
point in the best pose) raises :class:`~gaitopt.dynamics.reduced.ReachError`, which the solve
reports like an unreachable start of the two-link guess.
"""

from __future__ import annotations

from collections.abc import Mapping

import casadi as ca
import numpy as np

from gaitopt.dynamics.kinematics import contact_position
from gaitopt.dynamics.reduced import ReachError
from gaitopt.dynamics.tree import hold_name
from gaitopt.gait.guess.naive import (
    Array,
    PhaseGuess,
    WalkingGuess,
    knot_times,
    phase_guess,
    smoothstep,
)
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.sequence.contact_sequence import ContactSequence
from gaitopt.robot.model import BASE_ANGLE, BASE_X, BASE_Y, RobotModel

#: Samples per phase of the inverse kinematics (rates are differentiated from them).
SAMPLES = 60
#: Weights of the inverse-kinematics residuals: held points, swinging points, base path (per
#: metre on the reference biped's 1 m legs: distances are divided by ``l / l_ref``), torso,
#: joints (per radian).
W_HELD, W_SWING, W_BASE, W_TORSO, W_JOINT = 10.0, 1.0, 0.1, 0.3, 0.02
#: The pose the joints are pulled toward (rad): knees slightly flexed so that the inverse
#: kinematics stays on the knee-forward branch; other joints 0.
FLEXED_KNEE = -0.3
#: Largest distance (m, on the reference biped's 1 m legs; times ``l / l_ref`` on another
#: model, :mod:`gaitopt.gait.options.model_scale`) of a held point from its ground point in the
#: guess: farther, the
#: legs cannot reach the step (:class:`~gaitopt.dynamics.reduced.ReachError`). Measured over
#: the three naive steps at 3-150 m/min: the weighted compromise leaves held points up to
#: 1.1 cm off (the seven-link heel-toe walk at 60 m/min, 0.57 m), under 1 mm for the
#: knee-less biped; steps beyond the legs' reach miss by 5 cm and more.
PLACEMENT_TOL = 0.03


def _held_intervals(seq: ContactSequence, ends: Array, step: float
                    ) -> dict[str, list[tuple[float, float, float | None]]]:
    """Contact name -> ``(t0, t1, x)``: the time intervals of this period in which it is
    held and where (its ground x in that phase, None without an anchor)."""
    out: dict[str, list[tuple[float, float, float | None]]] = {}
    for i, ph in enumerate(seq.phases):
        anchored = seq.anchored(i)
        for spec in ph.held:
            c = hold_name(spec)
            x = seq.ground_x(c, step, i) if c in anchored else None
            out.setdefault(c, []).append((float(ends[i]), float(ends[i + 1]), x))
    return out


def _ground_points(seq: ContactSequence, swap: Mapping[str, str], step: float, total: float
                   ) -> dict[str, list[tuple[float, float, float | None]]]:
    """Contact -> held intervals ``(t0, t1, x)`` over five periods of ``total`` seconds
    (two before this one, two after: the point ``c`` is ``swap(c)`` one period later and
    ``c`` again two periods later, ``seq.steps L`` further each period; a stride's ``swap``
    is the identity), ``x`` its ground point or None without an anchor."""
    ends = np.concatenate([[0.0], np.cumsum([ph.fraction for ph in seq.phases])]) * total
    here = _held_intervals(seq, ends, step)
    length = seq.steps * step
    out: dict[str, list[tuple[float, float, float | None]]] = {}
    for c in {*here, *swap, *swap.values()}:
        rows: list[tuple[float, float, float | None]] = []
        for shift in (-2, -1, 0, 1, 2):
            name = c if shift % 2 == 0 else swap.get(c, c)
            for t0, t1, x in here.get(name, []):
                rows.append((t0 + shift * total, t1 + shift * total,
                             None if x is None else x + shift * length))
        out[c] = sorted(rows, key=lambda r: r[0])
    return out


#: A point's target at one time: ``(x or None, y or None, weight)``; None: no terms at all.
Target = tuple[float | None, float | None, float] | None


def _targets(rows: Mapping[str, list[tuple[float, float, float | None]]],
             bodies: Mapping[str, tuple[str, ...]], t: float, lift: float
             ) -> dict[str, Target]:
    """Each contact's target at time ``t`` from the held intervals ``rows`` (contact ->
    ``(t0, t1, x)``); ``bodies``: contact -> the contacts on its link (itself included).

    * held: its ground point, ``(x, 0)`` (``x`` None without an anchor), weight ``W_HELD``;
    * off the ground: the height ``lift sin(pi s_c)``, ``s_c`` the fraction of its own time
      off the ground (from its last ground point to its next), weight ``W_SWING``, so the
      height starts and ends at 0 where the point lifts and lands; where its whole link is
      off the ground also ``x``, from its last ground point to its next by smoothstep over
      the link's flight, ``s = (t - t_a) / (t_b - t_a)`` from the last of the link's points
      to leave the ground (``t_a``) to the first to come down (``t_b``): the points of one
      link share ``s``, so their targets keep the link's length; while another point of its
      link is held (a heel rising about the toe, a toe coming down after the heel) no
      ``x``: the held point and the pose place it;
    * no ground point before or after ``t``: None.
    """
    held = {c: next((r for r in rows.get(c, []) if r[0] - 1e-12 <= t <= r[1] + 1e-12), None)
            for c in bodies}
    before = {c: [r for r in rows.get(c, []) if r[1] < t] for c in bodies}
    after = {c: [r for r in rows.get(c, []) if r[0] > t] for c in bodies}
    out: dict[str, Target] = {}
    for c, mates in bodies.items():
        row = held[c]
        if row is not None:
            out[c] = (row[2], 0.0, W_HELD)
            continue
        if not before[c] or not after[c]:
            out[c] = None
            continue
        (_, ta, xa), (tb, _, xb) = before[c][-1], after[c][0]
        y = lift * float(np.sin(np.pi * (t - ta) / (tb - ta)))
        flying = all(before[m] and after[m] and held[m] is None for m in mates)
        if not flying or xa is None or xb is None:
            out[c] = (None, y, W_SWING)
            continue
        ta = max(before[m][-1][1] for m in mates)
        tb = min(after[m][0][0] for m in mates)
        s = (t - ta) / (tb - ta)
        out[c] = (xa + (xb - xa) * float(smoothstep(np.array(s))), y, W_SWING)
    return out


def _check_placed(model: RobotModel, phase: str, t: float, q: Array,
                  targets: Mapping[str, Target], step: float) -> None:
    """Raise :class:`ReachError` if a held point of the guess at time ``t`` is farther than
    :data:`PLACEMENT_TOL` from its ground point (the legs cannot reach it)."""
    for c, tgt in targets.items():
        if tgt is None or tgt[2] != W_HELD:
            continue
        p = np.asarray(contact_position(model, q, c), dtype=float).ravel()
        miss = float(np.hypot(0.0 if tgt[0] is None else p[0] - tgt[0], p[1]))
        if miss > model_scale(model).length(PLACEMENT_TOL):
            raise ReachError(
                f"the legs of model {model.name!r} cannot hold {c!r} on its ground point in "
                f"phase {phase!r} at t = {t:.3f} s of a {step:.3g} m step (the best pose "
                f"misses it by {miss:.3g} m)")


def contact_kinematics(model: RobotModel, names: list[str]) -> ca.Function:
    """CasADi function ``q (nq,) -> (P (2, n) m, dP/dq (2 n, nq))``: the world positions of
    the contacts ``names`` (column ``j`` is ``names[j]``; the expressions of
    :func:`~gaitopt.dynamics.kinematics.contact_position`, evaluated by CasADi's virtual
    machine instead of Python floats) and the Jacobian of ``P`` stacked by columns (row
    ``2 j + a`` is coordinate ``a`` of ``names[j]``)."""
    q = ca.SX.sym("q", model.nq)
    points = ca.horzcat(*[ca.vertcat(*ca.vertsplit(ca.SX(contact_position(model, q, c))))
                          for c in names])
    return ca.Function("contact_kinematics", [q],
                       [points, ca.jacobian(ca.vec(points), q)])


class _PoseFit:
    """The inverse kinematics' residual of one sample time and its exact Jacobian, for
    ``scipy.optimize.least_squares`` (the module docstring's terms; distances per reference
    leg length ``per_length``):

    * per targeted point ``c``: ``W_HELD (min(y_c, 0))`` (never below the ground), ``w_c (x_c -
      x*_c)`` where the target has an ``x``, ``w_c (y_c - y*_c)``;
    * ``W_BASE (x_b - x*_b)``, ``W_BASE (y_b - y*_b)``, ``W_TORSO theta_b``, ``W_JOINT (q_j -
      pose_j)``.

    The Jacobian comes from :func:`contact_kinematics` (the kinematics' own derivative; the
    finite differences it replaces took some 37,000 residual evaluations per guess of the
    seven-link, 8 s); ``min(y, 0)`` takes the derivative of ``y`` below the ground, 0 above.
    """

    def __init__(self, kinematics: ca.Function, names: list[str],
                 targets: Mapping[str, Target], base: tuple[float, float], pose: Array,
                 per_length: float) -> None:
        self.kinematics = kinematics
        self.pose = pose
        self.per_length = per_length
        self.base = base
        cols = [j for j, c in enumerate(names) if targets[c] is not None]
        tgts = [targets[names[j]] for j in cols]
        self.cols = np.array(cols, dtype=int)
        self.weights = np.array([t[2] for t in tgts if t is not None], dtype=float)
        with_x = [(k, t[0]) for k, t in enumerate(tgts) if t is not None and t[0] is not None]
        self.x_rows = np.array([k for k, _ in with_x], dtype=int)
        self.target_x = np.array([x for _, x in with_x], dtype=float)
        with_y = [(k, t[1]) for k, t in enumerate(tgts) if t is not None and t[1] is not None]
        self.y_rows = np.array([k for k, _ in with_y], dtype=int)
        self.target_y = np.array([y for _, y in with_y], dtype=float)
        nq = pose.size
        #: The rows of the base, torso and joint terms in the Jacobian (constant).
        self.fixed = np.zeros((nq, nq))
        self.fixed[0, BASE_X] = self.fixed[1, BASE_Y] = W_BASE * per_length
        self.fixed[2, BASE_ANGLE] = W_TORSO
        self.fixed[3:, 3:] = W_JOINT * np.eye(nq - 3)
        self._last: tuple[Array, Array, Array] | None = None

    def _evaluate(self, q: Array) -> tuple[Array, Array]:
        """The targeted points ``(2, n)`` and their Jacobian ``(n, 2, nq)`` at ``q`` (the last
        ``q``'s kept: the solver asks for the residual and then the Jacobian at a point)."""
        if self._last is None or not np.array_equal(self._last[0], q):
            points, jac = self.kinematics(np.asarray(q, dtype=float))
            self._last = (np.array(q, dtype=float), np.asarray(points)[:, self.cols],
                          np.asarray(jac).reshape(-1, 2, q.size)[self.cols])
        return self._last[1], self._last[2]

    def residual(self, q: Array) -> Array:
        p, _ = self._evaluate(q)
        pl, w = self.per_length, self.weights
        return np.concatenate([
            W_HELD * pl * np.minimum(p[1], 0.0),
            (w * pl)[self.x_rows] * (p[0, self.x_rows] - self.target_x),
            (w * pl)[self.y_rows] * (p[1, self.y_rows] - self.target_y),
            [W_BASE * pl * (q[BASE_X] - self.base[0]), W_BASE * pl * (q[BASE_Y] - self.base[1]),
             W_TORSO * q[BASE_ANGLE]],
            W_JOINT * (q[3:] - self.pose[3:])])

    def jacobian(self, q: Array) -> Array:
        p, d = self._evaluate(q)
        pl, w = self.per_length, self.weights
        return np.vstack([
            (W_HELD * pl * (p[1] < 0.0))[:, None] * d[:, 1],
            (w * pl)[self.x_rows, None] * d[self.x_rows, 0],
            (w * pl)[self.y_rows, None] * d[self.y_rows, 1],
            self.fixed])


def sequence_guess(model: RobotModel, seq: ContactSequence, swap: Mapping[str, str], *,
                   speed: float, step_length: float, knots: tuple[int, int], ankle: bool,
                   ankle_torques: bool | None = None, lift: float | None = None
                   ) -> WalkingGuess:
    """The guess of the module docstring, one :class:`PhaseGuess` per phase of ``seq`` (the
    knots of phase ``i`` are ``knots[min(i, 1)]``, as in the full-coordinate problem) over
    its period ``seq.steps L / v``; ``swap``: the contact renaming from the end of the period
    to its start (:meth:`ContactSequence.period_contacts` applies: none for a stride)."""
    # Imported here: SciPy's optimizer takes 0.8 s to import, and the paper's walk, which
    # imports this module with the staged solve, never calls it.
    from scipy.optimize import least_squares

    use_ankles = ankle if ankle_torques is None else ankle_torques and ankle
    v, step = speed, step_length
    swap = seq.period_contacts(swap)
    total = seq.steps * step / v
    # The swing arcs' height: on the reference biped (1 m legs) min(0.05, 0.015 + 0.1 L) m.
    scale = model_scale(model)
    lift = (lift if lift is not None else
            scale.length(min(0.05, 0.015 + 0.1 * step / scale.length_factor)))
    rows = _ground_points(seq, swap, step, total)
    per_length = 1.0 / scale.length_factor  # distances in reference leg lengths
    names = [c.name for c in model.contacts]
    zero = np.zeros(model.nq)
    stand = -min(float(contact_position(model, zero, c)[1]) for c in names)
    held_x = [x for c in names for (t0, t1, x) in rows.get(c, []) if x is not None
              and 0.0 <= t0 < total]
    middle = float(np.mean(held_x)) if held_x else 0.0
    lo = np.array([-np.inf, -np.inf, -np.pi] + [j.limits[0] for j in model.joints])
    hi = np.array([np.inf, np.inf, np.pi] + [j.limits[1] for j in model.joints])
    pose = np.array([0.0, 0.0, 0.0] + [FLEXED_KNEE if "knee" in j.name else 0.0
                                       for j in model.joints])
    q = np.clip(pose.copy(), lo, hi)
    q[BASE_X], q[BASE_Y] = middle - v * total / 2.0, 0.95 * stand
    ends = np.concatenate([[0.0], np.cumsum([ph.fraction for ph in seq.phases])]) * total
    kinematics = contact_kinematics(model, names)
    bodies = {c.name: tuple(o.name for o in model.contacts if o.link == c.link)
              for c in model.contacts}
    phases: list[PhaseGuess] = []
    for i, ph in enumerate(seq.phases):
        t_fine = np.linspace(ends[i], ends[i + 1], SAMPLES)
        q_fine = np.zeros((SAMPLES, model.nq))
        for k, t in enumerate(t_fine):
            targets = _targets(rows, bodies, float(t), lift)
            base = (middle + v * (t - total / 2.0), 0.95 * stand)

            fit = _PoseFit(kinematics, names, targets, base, pose, per_length)
            q = least_squares(fit.residual, np.clip(q, lo + 1e-9, hi - 1e-9), jac=fit.jacobian,
                              bounds=(lo, hi), xtol=1e-10, ftol=1e-10).x
            q_fine[k] = q
            _check_placed(model, ph.name, float(t), q, targets, step)
        count = knots[min(i, 1)]
        phases.append(phase_guess(model, ph.name, t_fine, q_fine,
                                  knot_times(float(ends[i]), float(ends[i + 1] - ends[i]), count),
                                  ankle, use_ankles, list(ph.held), True))
    return WalkingGuess(phases=tuple(phases),
                        parameters={"step_length": step, "speed": v, "impulse": 0.0})
