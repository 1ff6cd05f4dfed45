"""Normal-only holds (``name:y``): a flat foot, heel pinned and toe held along the normal.

Pinning both points of one rigid foot states its three constraints four times (a singular
``J M^-1 J^T``); holding the toe along y only keeps them independent. References: the KKT
system with Pinocchio's ``M``, ``h``, ``J`` and ``Jdot qd`` restricted to the held rows, and
rigid-body facts (a flat foot held this way does not move at all).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from dynamics_helpers import assert_close
from pinocchio_model import build

from gaitopt.dynamics import contact_acceleration, contact_dynamics, contact_velocity, impact
from gaitopt.dynamics.kinematics import contact_jacobian, contact_position
from gaitopt.dynamics.tree import hold_rows, holds
from gaitopt.robot import RobotModel
from gaitopt.robot.loader import load_model


@pytest.fixture(scope="module")
def seven() -> RobotModel:
    return load_model("seven-link")


def flat_foot_state(model: RobotModel, rng: np.random.Generator
                    ) -> tuple[np.ndarray, np.ndarray]:
    """A configuration with foot 1 flat on the ground (heel at the origin) and velocities
    with foot 1 at rest: the base placed by the foot, the other joints random."""
    q = 0.3 * rng.normal(size=model.nq)
    q[2] = 0.1 * rng.normal()
    # Absolute angle of foot 1 = torso + hip_1 + knee_1 + ankle_1 = 0 (flat sole).
    i_h, i_k, i_a = (model.coordinate_names.index(n) for n in ("hip_1", "knee_1", "ankle_1"))
    q[i_k] = -abs(q[i_k])
    q[i_a] = -(q[2] + q[i_h] + q[i_k])
    q[:2] = 0.0
    heel = np.asarray(contact_position(model, q, "heel_1"), dtype=float).ravel()
    q[:2] -= heel
    jac = np.asarray(contact_jacobian(model, q, ["heel_1", "toe_1"]), dtype=float).reshape(
        4, model.nq)
    qd = rng.normal(size=model.nq)
    qd -= np.linalg.pinv(jac) @ (jac @ qd)   # project onto the foot at rest
    return q, qd


def test_flat_foot_rows_and_parsing(seven: RobotModel) -> None:
    assert hold_rows(seven, ["heel_1", "toe_1:y"]) == 3
    assert [h.axes for h in holds(seven, ["heel_1", "toe_1:y", "toe_2:xy"])] == [
        (0, 1), (1,), (0, 1)]
    with pytest.raises(ValueError, match=r"toe_1:z.*one of xy, y"):
        holds(seven, ["toe_1:z"])
    with pytest.raises(ValueError, match="no contact point 'toe_9'"):
        holds(seven, ["toe_9:y"])


def test_flat_foot_dynamics_solve_the_kkt_system(seven: RobotModel) -> None:
    """KKT with Pinocchio over the rows heel x, heel y, toe y; the toe's x acceleration
    follows (the foot is at rest and stays flat), and pinning both points is refused."""
    ref = build(seven)
    pm, pd, P, back = ref.model, ref.data(), ref.to_pin, ref.from_pin
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, qd = flat_foot_state(seven, rng)
        tau = 20.0 * rng.normal(size=seven.nq)
        sol = contact_dynamics(seven, q, qd, tau, ["heel_1", "toe_1:y"])
        m = pin.crba(pm, pd, P(q))
        m = back(np.triu(m) + np.triu(m, 1).T)
        # Pinocchio has no joint damping: the model's (the ankles') is added as D qd.
        h = back(pin.nonLinearEffects(pm, pd, P(q), P(qd)))
        h = h + np.asarray(seven.coordinate_damping) * qd
        pin.computeJointJacobians(pm, pd, P(q))
        pin.forwardKinematics(pm, pd, P(q), P(qd), np.zeros(seven.nq))
        pin.updateFramePlacements(pm, pd)
        frame = pin.LOCAL_WORLD_ALIGNED
        rows = [("heel_1", 0), ("heel_1", 1), ("toe_1", 1)]
        jac = np.vstack([back(pin.getFrameJacobian(pm, pd, ref.contact_frames[c], frame)[a])
                         for c, a in rows])
        jdot_qd = np.array([pin.getFrameClassicalAcceleration(
            pm, pd, ref.contact_frames[c], frame).linear[a] for c, a in rows])
        kkt = np.block([[m, -jac.T], [jac, np.zeros((3, 3))]])
        x = np.linalg.solve(kkt, np.concatenate([tau - h, -jdot_qd]))
        assert_close(sol.qdd, x[:seven.nq], rtol=1e-8, what="qdd")
        assert_close(sol.forces, x[seven.nq:], rtol=1e-8, what="forces")
        for c in ("heel_1", "toe_1"):
            vel = np.asarray(contact_velocity(seven, q, qd, c), dtype=float)
            np.testing.assert_allclose(vel.ravel(), 0.0, atol=1e-12, err_msg="foot at rest")
            acc = np.asarray(contact_acceleration(seven, q, qd, sol.qdd, c), dtype=float)
            np.testing.assert_allclose(acc.ravel(), 0.0, atol=1e-9, err_msg=f"{c} acc.")
        with pytest.raises(ValueError, match="redundant"):
            contact_dynamics(seven, q, qd, tau, ["heel_1", "toe_1"])


def test_foot_flat_impact_stops_the_foot(seven: RobotModel) -> None:
    """The toe striking while the heel is pinned (``heel_1``, ``toe_1:y``): afterwards both
    points are at rest in x and y, the kinetic energy does not grow, and the impulses are
    those of the KKT impact system (M dqd = J^T P, J qd+ = 0) on the three rows."""
    from gaitopt.dynamics.crba import crba
    from gaitopt.dynamics.energy import kinetic_energy

    rng = np.random.default_rng(8)
    q, qd = flat_foot_state(seven, rng)
    qd_minus = qd + 0.5 * rng.normal(size=seven.nq)
    sol = impact(seven, q, qd_minus, ["heel_1", "toe_1:y"])
    qd_plus = np.asarray(sol.qd_plus, dtype=float).ravel()
    for c in ("heel_1", "toe_1"):
        vel = np.asarray(contact_velocity(seven, q, qd_plus, c), dtype=float)
        np.testing.assert_allclose(vel.ravel(), 0.0, atol=1e-10, err_msg=f"{c} after")
    assert float(kinetic_energy(seven, q, qd_plus)) <= float(kinetic_energy(seven, q,
                                                                             qd_minus)) + 1e-12
    m = np.asarray(crba(seven, q), dtype=float)
    jac = np.asarray(contact_jacobian(seven, q, ["heel_1", "toe_1:y"]),
                     dtype=float).reshape(3, seven.nq)
    kkt = np.block([[m, -jac.T], [jac, np.zeros((3, 3))]])
    x = np.linalg.solve(kkt, np.concatenate([m @ qd_minus, np.zeros(3)]))
    assert_close(qd_plus, x[:seven.nq], rtol=1e-9, what="qd_plus")
    assert_close(sol.impulses, x[seven.nq:], rtol=1e-9, what="impulses")
