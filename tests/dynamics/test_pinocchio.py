"""Our recursive algorithms against Pinocchio on the same models at random states."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from dynamics_helpers import assert_close, random_state
from pinocchio_model import build

from gaitopt.dynamics import (
    aba,
    bias_forces,
    contact_jacobian,
    crba,
    link_angles,
    link_frames,
    point_acceleration,
    point_jacobian,
    point_position,
    point_velocity,
    rnea,
)
from gaitopt.robot import RobotModel

N_STATES = 100


def full_mass_matrix(pm: pin.Model, pd: pin.Data, q: np.ndarray) -> np.ndarray:
    m = pin.crba(pm, pd, q)
    return np.triu(m) + np.triu(m, 1).T


def test_mass_matrix_inverse_and_forward_dynamics(model: RobotModel) -> None:
    ref = build(model)
    pm, pd, P, back = ref.model, ref.data(), ref.to_pin, ref.from_pin
    rng = np.random.default_rng(10)
    for _ in range(N_STATES):
        q, qd, qdd = random_state(rng, model.nq)
        tau = 20.0 * rng.normal(size=model.nq)
        assert_close(crba(model, q), back(full_mass_matrix(pm, pd, P(q))), what="M")
        assert_close(rnea(model, q, qd, qdd), back(pin.rnea(pm, pd, P(q), P(qd), P(qdd))),
                     what="rnea")
        assert_close(bias_forces(model, q, qd),
                     back(pin.nonLinearEffects(pm, pd, P(q), P(qd))), what="bias")
        assert_close(aba(model, q, qd, tau), back(pin.aba(pm, pd, P(q), P(qd), P(tau))),
                     what="aba")


def test_point_kinematics(model: RobotModel) -> None:
    ref = build(model)
    rng = np.random.default_rng(11)
    # One random point on every link.
    points = [(i, (float(rng.uniform(-0.5, 1.0)), float(rng.uniform(-0.3, 0.3))))
              for i in range(len(model.links))]
    frame_ids = [ref.add_point_frame(i, p, f"p{i}") for i, p in points]
    pm, pd, P, back = ref.model, ref.data(), ref.to_pin, ref.from_pin
    for _ in range(N_STATES):
        q, qd, qdd = random_state(rng, model.nq)
        pin.forwardKinematics(pm, pd, P(q), P(qd), P(qdd))
        pin.updateFramePlacements(pm, pd)
        pin.computeJointJacobians(pm, pd, P(q))
        for (i, p), fid in zip(points, frame_ids, strict=True):
            assert_close(point_position(model, q, i, p), pd.oMf[fid].translation[:2],
                         what="position")
            frame = pin.LOCAL_WORLD_ALIGNED
            assert_close(point_velocity(model, q, qd, model.links[i].name, p),
                         pin.getFrameVelocity(pm, pd, fid, frame).linear[:2], what="velocity")
            assert_close(point_acceleration(model, q, qd, qdd, i, p),
                         pin.getFrameClassicalAcceleration(pm, pd, fid, frame).linear[:2],
                         what="acceleration")
            assert_close(point_jacobian(model, q, i, p),
                         back(pin.getFrameJacobian(pm, pd, fid, frame)[:2]), what="jacobian")
        angles = link_angles(model, q)
        frames = link_frames(model, q)
        for i, jid in ref.joint_of_link.items():
            rot = pd.oMi[jid].rotation
            assert_close([np.cos(angles[i]), np.sin(angles[i])], rot[:2, 0], what="angle")
            assert_close(frames[i].origin, pd.oMi[jid].translation[:2], what="origin")


def test_contact_jacobian_matches_frames(model: RobotModel) -> None:
    ref = build(model)
    pm, pd = ref.model, ref.data()
    rng = np.random.default_rng(12)
    names = [c.name for c in model.contacts]
    for _ in range(20):
        q, _, _ = random_state(rng, model.nq)
        pin.computeJointJacobians(pm, pd, ref.to_pin(q))
        pin.updateFramePlacements(pm, pd)
        expected = np.vstack([ref.from_pin(pin.getFrameJacobian(
            pm, pd, ref.contact_frames[n], pin.LOCAL_WORLD_ALIGNED)[:2]) for n in names])
        assert_close(contact_jacobian(model, q, names), expected, what="J_contact")
