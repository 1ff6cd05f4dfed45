"""Shared fixtures and independent checks for the walking-problem tests.

Solving is the expensive part: :func:`solved` memoises solves for the whole session (keyed
by the model's content hash and the options), so the default gait of the paper is solved once
and every test module that needs it, or a variant, shares the result. The solver's own
process-wide transcription cache (:func:`gaitopt.gait.solve.staged.transcription_for`) means a
variant that differs from an earlier solve only in its speed or step length reuses the NLP.

The checks here never use the solver's equations: the equations of motion, contact
Jacobians, tip kinematics and actuation come from Pinocchio
(``tests/dynamics/pinocchio_model.py`` builds the same tree from the model data), and
periodicity uses the model's leg-swap maps.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.typing import NDArray

from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions, follows_model
from gaitopt.gait.record.file import Gait, GaitPhase
from gaitopt.gait.solve.record import gait_from_run
from gaitopt.gait.solve.staged import StagedRun
from gaitopt.robot import RobotModel, load_model
from gaitopt.robot.symmetry import swap_matrices
from tests.dynamics.pinocchio_model import PinModel, build

Array = NDArray[np.float64]

#: Absolute tolerance of the equations of motion residual relative to their size (N, N m),
#: and of the tips held on the ground: position (m), velocity (m/s), acceleration (m/s^2).
#: Full-coordinate solves meet both as constraints to their tolerance (tol 1e-7), so the
#: margin is 10 x that (a rule of docs/testing.md).
EOM_RTOL = 1e-6
TIP_TOL = 1e-6


# -- solving once per session -------------------------------------------------------------------

@dataclass(frozen=True)
class Solved:
    """A solve and its gait record."""

    solution: StagedRun
    gait: Gait


SolveFn = Callable[..., Solved]


def model_defaults(options: GaitOptions) -> tuple[str, ...]:
    """The fields of ``options`` still left to the model (``follows_model``): a default knot
    grid and the same grid given explicitly print alike, but only the first refines itself, so
    the memo key must tell them apart."""
    return tuple(f"{group.name}.{field.name}"
                 for group in dataclasses.fields(options)
                 for field in dataclasses.fields(getattr(options, group.name))
                 if follows_model(getattr(getattr(options, group.name), field.name)))


@pytest.fixture(scope="session")
def five() -> RobotModel:
    """The five-link biped (the built-in model)."""
    return load_model("five-link")


@pytest.fixture(scope="session")
def seven() -> RobotModel:
    """The seven-link biped with feet (the built-in model)."""
    return load_model("seven-link")


@pytest.fixture(scope="session")
def solved() -> Iterator[SolveFn]:
    """``solved(options=GaitOptions.paper(), model="five-link") -> Solved``, memoised per
    session."""
    cache: dict[tuple[str, str], Solved] = {}

    def solve(options: GaitOptions | None = None,
              model: RobotModel | str = "five-link") -> Solved:
        robot = model if isinstance(model, RobotModel) else load_model(model)
        opts = options or GaitOptions.paper()
        key = (robot.content_hash(), repr(opts), model_defaults(opts))
        if key not in cache:
            solution = solve_staged_run(robot, opts)
            cache[key] = Solved(solution, gait_from_run(solution))
        return cache[key]

    yield solve


@pytest.fixture(scope="session")
def default_solved(solved: SolveFn) -> Solved:
    """The paper's problem: ``GaitOptions.paper()`` (12 m/min, ankle + impulse, step length
    free, 8 + 5 knots, the paper's control model) on the built-in five-link biped."""
    return solved(GaitOptions.paper())


@pytest.fixture(scope="session")
def default_gait(default_solved: Solved) -> Gait:
    return default_solved.gait


@pytest.fixture(scope="session")
def default_gait_file(default_gait: Gait, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The default gait saved as a gait file (shared, never modify it: copy it)."""
    return default_gait.save(tmp_path_factory.mktemp("default") / "default.gait.json")


# -- independent physics (Pinocchio) ------------------------------------------------------------

@dataclass
class Reference:
    """Pinocchio's model of a gaitopt model, with the helpers the walking checks need."""

    model: RobotModel
    pin: PinModel

    def __post_init__(self) -> None:
        self.data = self.pin.data()

    def _update(self, q: Array, qd: Array | None = None, qdd: Array | None = None) -> None:
        P = self.pin.to_pin
        pm, pd = self.pin.model, self.data
        zero = np.zeros(self.model.nq)
        pin.forwardKinematics(pm, pd, P(q), P(zero if qd is None else qd),
                              P(zero if qdd is None else qdd))
        pin.computeJointJacobians(pm, pd, P(q))
        pin.updateFramePlacements(pm, pd)

    def mass_matrix(self, q: Array) -> Array:
        """M(q) (nq, nq) in gaitopt's coordinate order (Pinocchio's CRBA, symmetrised)."""
        m = pin.crba(self.pin.model, self.data, self.pin.to_pin(q))
        m = np.triu(m) + np.triu(m, 1).T
        return np.asarray(self.pin.from_pin(m), dtype=float)

    def bias(self, q: Array, qd: Array) -> Array:
        """h(q, qd) = C(q, qd) qd + g(q) + D qd (nq,): Pinocchio's RNEA with qdd = 0, plus the
        joints' viscous damping ``D = diag(b)`` from the model data (Pinocchio's RNEA leaves
        damping out; the seven-link's ankles have b = 2 N m s/rad)."""
        P = self.pin.to_pin
        h = pin.rnea(self.pin.model, self.data, P(q), P(qd), np.zeros(self.model.nq))
        damping = np.asarray(self.model.coordinate_damping, dtype=float)
        return np.asarray(self.pin.from_pin(h), dtype=float) + damping * np.asarray(qd)

    def contact_jacobian(self, q: Array, contact: str) -> Array:
        """Linear world-frame Jacobian (2, nq) of a contact point."""
        self._update(q)
        fid = self.pin.contact_frames[contact]
        j = pin.getFrameJacobian(self.pin.model, self.data, fid, pin.LOCAL_WORLD_ALIGNED)[:2]
        return np.asarray(self.pin.from_pin(j), dtype=float)

    def tip_kinematics(self, q: Array, qd: Array, qdd: Array,
                       contact: str) -> tuple[Array, Array, Array]:
        """World position (2,), velocity (2,) and classical acceleration (2,) of a tip."""
        self._update(q, qd, qdd)
        pm, pd = self.pin.model, self.data
        fid = self.pin.contact_frames[contact]
        frame = pin.LOCAL_WORLD_ALIGNED
        return (np.array(pd.oMf[fid].translation[:2]),
                np.array(pin.getFrameVelocity(pm, pd, fid, frame).linear[:2]),
                np.array(pin.getFrameClassicalAcceleration(pm, pd, fid, frame).linear[:2]))

    def actuation(self, q: Array, held: tuple[str, ...]) -> Array:
        """B (nq, nu): a joint torque on its joint's velocity coordinate; an ankle torque of a
        held tip as a pure moment on the tip's link, i.e. the link's angular Jacobian row
        (1 on the torso angle, the hip and the knee of that leg); an ankle of a tip in the
        air contributes nothing."""
        m, pm = self.model, self.pin.model
        b = np.zeros((m.nq, m.nu))
        self._update(q)
        for j, act in enumerate(m.actuators):
            if act.joint is not None:
                link = next(i for i, link in enumerate(m.links)
                            if link.joint is not None and link.joint.name == act.joint)
                col = np.zeros(m.nq)
                col[pm.joints[self.pin.joint_of_link[link]].idx_v] = 1.0
                b[:, j] = self.pin.from_pin(col)
            elif act.contact in held:
                fid = self.pin.contact_frames[act.contact]
                jac = pin.getFrameJacobian(pm, self.data, fid, pin.LOCAL_WORLD_ALIGNED)
                b[:, j] = self.pin.from_pin(jac[5])  # angular velocity about z
        return b


@pytest.fixture(scope="session")
def reference() -> Callable[[RobotModel], Reference]:
    """``reference(model)``: the Pinocchio reference of a model (memoised)."""
    cache: dict[str, Reference] = {}

    def get(model: RobotModel) -> Reference:
        key = model.content_hash()
        if key not in cache:
            cache[key] = Reference(model, build(model))
        return cache[key]

    return get


def eom_residuals(ref: Reference, phase: GaitPhase) -> Array:
    """Per knot, the largest |M qdd + h - B u - J_c^T f| relative to the largest term (K,).

    ``f`` stacks the saved contact forces of the phase's contacts (world frame, force of the
    ground on the tip), ``J_c`` their Jacobians."""
    out = []
    for k in range(phase.t.size):
        q, qd, qdd, u = phase.q[k], phase.qd[k], phase.qdd[k], phase.u[k]
        lhs = ref.mass_matrix(q) @ qdd + ref.bias(q, qd)
        b_u = ref.actuation(q, phase.contacts) @ u
        jt_f = sum((ref.contact_jacobian(q, c).T @ phase.contact_forces[c][k]
                    for c in phase.contacts), start=np.zeros(ref.model.nq))
        residual = lhs - b_u - jt_f
        size = max(np.max(np.abs(lhs)), np.max(np.abs(b_u)), np.max(np.abs(jt_f)), 1.0)
        out.append(float(np.max(np.abs(residual)) / size))
    return np.array(out)


def held_tip_errors(ref: Reference, gait: Gait) -> dict[str, float]:
    """Largest position error from (0, 0) / (L, 0), velocity and acceleration of every tip in
    contact at every knot of every phase (m, m/s, m/s^2)."""
    legs = [c.name for c in gait.model.contacts]
    at = {legs[0]: np.zeros(2), legs[1]: np.array([gait.step_length, 0.0])}
    err = {"position": 0.0, "velocity": 0.0, "acceleration": 0.0}
    for ph in gait.phases:
        for c in ph.contacts:
            for k in range(ph.t.size):
                p, v, a = ref.tip_kinematics(ph.q[k], ph.qd[k], ph.qdd[k], c)
                err["position"] = max(err["position"], float(np.max(np.abs(p - at[c]))))
                err["velocity"] = max(err["velocity"], float(np.max(np.abs(v))))
                err["acceleration"] = max(err["acceleration"], float(np.max(np.abs(a))))
    return err


def assert_physics(ref: Reference, gait: Gait) -> None:
    """Every knot of every phase satisfies Pinocchio's equations of motion with the saved
    forces, and every tip in contact is at its point with zero velocity and acceleration."""
    assert gait.success
    for ph in gait.phases:
        res = eom_residuals(ref, ph)
        assert np.all(res < EOM_RTOL), f"{ph.name}: EOM residual {res.max():.2e} (per knot {res})"
    err = held_tip_errors(ref, gait)
    assert err["position"] < TIP_TOL, err
    assert err["velocity"] < TIP_TOL, err
    assert err["acceleration"] < 1e-6, err


def periodicity_errors(gait: Gait, *, controls: tuple[str, ...]) -> tuple[float, float]:
    """Largest state and control mismatch between the start of the step and the end of the
    step (after the liftoff event) with the legs swapped and x shifted back by one step.

    ``controls``: the actuator names compared (those acting at the start of the step)."""
    model = gait.model
    s_q, s_u = swap_matrices(model)
    first, last = gait.phases[0], gait.phases[-1]
    liftoff = next(e for e in gait.events if e.name == "liftoff")
    q_next = s_q @ last.q[-1]
    q_next[0] -= gait.step_length
    qd_next = s_q @ liftoff.qd_after
    state = max(float(np.max(np.abs(q_next - first.q[0]))),
                float(np.max(np.abs(qd_next - first.qd[0]))))
    cols = [model.actuator_index(a) for a in controls]
    u_next = s_u @ last.u[-1]
    control = float(np.max(np.abs(u_next[cols] - first.u[0][cols]), initial=0.0))
    return state, control


def recomputed_cost(gait: Gait) -> float:
    """(integral of u'u over the step + P^2) / L (a stride: over both steps, + 2 P^2, / 2 L)
    from the saved knots, independent of the solver: Simpson's rule per interval on the
    piecewise-linear controls (exact for their square, a quadratic)."""
    total = 0.0
    for ph in gait.phases:
        for k in range(ph.t.size - 1):
            h = ph.t[k + 1] - ph.t[k]
            a, b = ph.u[k], ph.u[k + 1]
            mid = 0.5 * (a + b)
            total += h / 6.0 * float(a @ a + 4.0 * mid @ mid + b @ b)
    p = gait.parameters["liftoff_impulse"]
    steps = gait.period_steps  # a stride: two steps, two liftoffs, 2 L
    return (total + steps * p * p) / (steps * gait.step_length)


def contact_forces(ref: Reference, q: Array, qd: Array, u: Array,
                   held: tuple[str, ...]) -> Array:
    """Contact forces (len(held), 2) of the ground on the held tips (world frame, N) for full
    actuator torques ``u`` (nu,): the solution of

        [[M, -J^T], [J, 0]] [qdd; f] = [B u - h; -Jdot qd]

    with Pinocchio's M, h, J and ``Jdot qd`` (the tips' classical acceleration at qdd = 0)."""
    nq = ref.model.nq
    jac = np.vstack([ref.contact_jacobian(q, c) for c in held])
    jdot_qd = np.concatenate([ref.tip_kinematics(q, qd, np.zeros(nq), c)[2] for c in held])
    m = ref.mass_matrix(q)
    kkt = np.block([[m, -jac.T], [jac, np.zeros((jac.shape[0], jac.shape[0]))]])
    rhs = np.concatenate([ref.actuation(q, held) @ u - ref.bias(q, qd), -jdot_qd])
    sol = np.linalg.solve(kkt, rhs)
    return sol[nq:].reshape(len(held), 2)


def lowest_sample_normal_force(ref: Reference, gait: Gait) -> float:
    """The smallest normal force (N) over the dense samples, each sample evaluated with the
    contacts of its own phase: single support up to and including the heel strike (that
    sample holds the pre-impact velocity), double support after it."""
    s = gait.samples
    strike = next(e for e in gait.events if e.name == "heel_strike")
    lowest = np.inf
    for i, ph in enumerate(gait.phases):
        inside = (s.t <= strike.t) if i == 0 else (s.t > strike.t)
        for k in np.flatnonzero(inside):
            f = contact_forces(ref, s.q[k], s.qd[k], s.u[k], ph.contacts)
            lowest = min(lowest, float(np.min(f[:, 1])))
    return lowest
