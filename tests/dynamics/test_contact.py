"""Contact Algorithm (paper eqs. 7-10) against the KKT system, with Pinocchio's M and J."""

from __future__ import annotations

import itertools

import numpy as np
import pinocchio as pin
import pytest
from dynamics_helpers import assert_close, random_state, well_conditioned
from pinocchio_model import build

from gaitopt.dynamics import (
    actuation_matrix,
    contact_acceleration,
    contact_dynamics,
    contact_jacobian,
    generalized_forces,
    link_angles,
    point_velocity,
)
from gaitopt.dynamics.tree import contact_point
from gaitopt.robot import RobotModel


def contact_sets(model: RobotModel) -> list[tuple[str, ...]]:
    names = [c.name for c in model.contacts]
    return [(n,) for n in names] + list(itertools.combinations(names, 2))


def test_forces_solve_the_kkt_system(model: RobotModel) -> None:
    """[M -J^T; J 0] [qdd; f] = [tau - h; -Jdot qd] with M, h, J, Jdot qd from Pinocchio."""
    ref = build(model)
    pm, pd, P, back = ref.model, ref.data(), ref.to_pin, ref.from_pin
    rng = np.random.default_rng(20)
    for contacts in contact_sets(model):
        for _ in range(15):
            q, qd, _ = random_state(rng, model.nq)
            if not well_conditioned(model, q, contacts):
                continue
            tau = 10.0 * rng.normal(size=model.nq)
            sol = contact_dynamics(model, q, qd, tau, contacts)
            m = pin.crba(pm, pd, P(q))
            m = back(np.triu(m) + np.triu(m, 1).T)
            h = back(pin.nonLinearEffects(pm, pd, P(q), P(qd)))
            pin.computeJointJacobians(pm, pd, P(q))
            pin.forwardKinematics(pm, pd, P(q), P(qd), np.zeros(model.nq))
            pin.updateFramePlacements(pm, pd)
            frame = pin.LOCAL_WORLD_ALIGNED
            jac = np.vstack([back(pin.getFrameJacobian(pm, pd, ref.contact_frames[c], frame)[:2])
                             for c in contacts])
            jdot_qd = np.concatenate([pin.getFrameClassicalAcceleration(
                pm, pd, ref.contact_frames[c], frame).linear[:2] for c in contacts])
            nc2 = jac.shape[0]
            kkt = np.block([[m, -jac.T], [jac, np.zeros((nc2, nc2))]])
            x = np.linalg.solve(kkt, np.concatenate([tau - h, -jdot_qd]))
            assert_close(sol.qdd, x[:model.nq], rtol=1e-8, what="qdd")
            assert_close(sol.forces, x[model.nq:], rtol=1e-8, what="forces")
            lam = np.linalg.inv(jac @ np.linalg.solve(m, jac.T))
            assert_close(sol.Lambda, lam, rtol=1e-8, what="Lambda")
            # Constrained tip accelerations are zero.
            for c in contacts:
                assert_close(contact_acceleration(model, q, qd, sol.qdd, c), np.zeros(2),
                             rtol=1e-9, what="tip acceleration")


def test_no_contacts_is_free_dynamics(five_link: RobotModel) -> None:
    from gaitopt.dynamics import aba

    rng = np.random.default_rng(21)
    q, qd, _ = random_state(rng, five_link.nq)
    tau = rng.normal(size=five_link.nq)
    sol = contact_dynamics(five_link, q, qd, tau, ())
    assert_close(sol.qdd, aba(five_link, q, qd, tau))
    assert sol.forces.shape == (0,) and sol.Lambda.shape == (0, 0)


def test_joint_actuators_act_on_their_coordinate(five_link: RobotModel) -> None:
    u = np.arange(1.0, 7.0)  # hip_1, knee_1, ankle_1, hip_2, knee_2, ankle_2
    q = np.zeros(7)
    tau = generalized_forces(five_link, q, u, ())
    # Ankles inactive without contact; hips and knees on their own coordinates.
    assert_close(tau, [0, 0, 0, 1, 2, 4, 5])
    b = actuation_matrix(five_link, q, ["tip_1"])
    assert b.shape == (7, 6)
    assert_close(b @ u, generalized_forces(five_link, q, u, ["tip_1"]))


def test_ankle_moment_by_virtual_power(model: RobotModel) -> None:
    """The generalized force of a pure moment tau on the tip's link does power
    ``tau * omega_link`` for any velocity: B[:, ankle] . qd = omega of that link."""
    rng = np.random.default_rng(22)
    names = [c.name for c in model.contacts]
    for _ in range(10):
        q, qd, _ = random_state(rng, model.nq)
        b = actuation_matrix(model, q, names)
        for j, act in enumerate(model.actuators):
            if act.contact is None:
                continue
            link, p = contact_point(model, act.contact)
            # omega = (v(p + e_perp) - v(p)) . rotated unit vector, by rigid-body kinematics
            p2 = (p[0] + 1.0, p[1])
            v1 = point_velocity(model, q, qd, link, p)
            v2 = point_velocity(model, q, qd, link, p2)
            d = np.asarray(v2) - np.asarray(v1)  # = omega x R e_x
            phi = link_angles(model, q)[link]
            omega = d @ np.array([-np.sin(phi), np.cos(phi)])
            assert b[:, j] @ qd == pytest.approx(omega, rel=1e-12, abs=1e-12)
        b_none = actuation_matrix(model, q, ())
        ankle_cols = [j for j, a in enumerate(model.actuators) if a.contact is not None]
        assert np.all(b_none[:, ankle_cols] == 0.0)


def test_double_support_jacobian_rank(five_link: RobotModel) -> None:
    q = np.array([0.2, 0.9, 0.1, 0.4, -0.3, -0.3, -0.1])
    jac = contact_jacobian(five_link, q, ["tip_1", "tip_2"])
    assert jac.shape == (4, 7) and np.linalg.matrix_rank(jac) == 4
