"""The MJCF export (``gaitopt.robot.mjcf_export``) against gaitopt's own dynamics.

MuJoCo's joint-space mass matrix (``mj_fullM``) and bias forces (``qfrc_bias``: Coriolis,
centrifugal and gravity) at random states equal gaitopt's CRBA and RNEA (``crba``,
``bias_forces``) under the coordinate map ``qpos = S P q``, ``qvel = S P qd`` (``S`` diagonal,
-1 on the base angle; ``P`` MuJoCo's depth-first order of the joints, by name):
``M_mj = S P M P^T S`` and ``bias_mj = S P bias``. An independent check of the
export's frames, signs, inertials and gravity: MuJoCo computes both with its own algorithms.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

from gaitopt.analysis.mujoco_model import mujoco_robot
from gaitopt.dynamics import bias_forces, contact_position, crba
from gaitopt.robot import RobotModel, load_model
from gaitopt.robot.mjcf_export import MjcfContact, mjcf_from_model

os.environ.setdefault("MUJOCO_GL", "egl")  # before MuJoCo loads (the simulate tests render)
mujoco = pytest.importorskip("mujoco")
sys.path.insert(0, str(Path(__file__).parents[1] / "dynamics"))
from dynamics_helpers import random_tree  # noqa: E402


def _models() -> list[RobotModel]:
    return [load_model("five-link"), load_model("seven-link"), random_tree(3, n_links=7),
            random_tree(11), _point_masses()]


def _point_masses() -> RobotModel:
    """The kneed compass gait after Drake's: point-mass legs (inertia 0), which MuJoCo refuses
    unless the export bounds them (BOUND_INERTIA)."""
    from gaitopt.robot.urdf import import_urdf

    path = Path(__file__).parent / "data" / "kneed_compass_gait.urdf"
    return import_urdf(path).model


@pytest.mark.parametrize("model", _models(), ids=lambda m: m.name)
def test_mass_matrix_and_bias_equal_gaitopts(model: RobotModel) -> None:
    robot = mujoco_robot(model)
    mj, cmap = robot.mj, robot.coordinates
    data = mujoco.MjData(mj)
    assert mj.nq == mj.nv == model.nq
    # qpos = (x, z, rooty, joints...) in MuJoCo's depth-first order; rooty = -angle
    assert list(cmap.sign[:3]) == [1.0, 1.0, -1.0] and set(cmap.sign[3:]) == {1.0}
    assert list(cmap.index[:3]) == [0, 1, 2] and not cmap.offset.any()
    perm = np.argsort(cmap.index)  # MuJoCo coordinate k is gaitopt coordinate perm[k]
    rng = np.random.default_rng(7)
    full = np.zeros((mj.nv, mj.nv))
    for _ in range(10):
        q = rng.uniform(-np.pi, np.pi, model.nq)
        q[:2] = rng.uniform(-2.0, 2.0, 2)
        qd = rng.normal(size=model.nq)
        cmap.set_state(data, q, qd)
        np.testing.assert_allclose(cmap.q(data.qpos), q, rtol=0, atol=1e-15)
        mujoco.mj_forward(mj, data)
        mujoco.mj_fullM(mj, data, full)  # MuJoCo 4 signature
        m_ref = np.asarray(crba(model, q), dtype=float)
        b_ref = np.asarray(bias_forces(model, q, qd), dtype=float).ravel()
        s = cmap.sign[perm]
        np.testing.assert_allclose(full, np.outer(s, s) * m_ref[np.ix_(perm, perm)], rtol=0,
                                   atol=1e-9 * np.abs(m_ref).max())
        # gaitopt's bias includes the joints' damping D qd, MuJoCo's passive force is -D qd.
        np.testing.assert_allclose(data.qfrc_bias - data.qfrc_passive, s * b_ref[perm],
                                   rtol=0, atol=1e-9 * max(1.0, np.abs(b_ref).max()))


def test_contact_spheres_sit_at_the_contact_points() -> None:
    """Each contact sphere's centre is gaitopt's contact point (MuJoCo (x, z)), and the ground
    plane is one radius below gaitopt's ground."""
    model = load_model("seven-link")
    radius = 0.004
    mj = mujoco.MjModel.from_xml_string(mjcf_from_model(model,
                                                        contact=MjcfContact(radius=radius)))
    data = mujoco.MjData(mj)
    q = np.array([0.3, 0.9, 0.1, 0.4, -0.3, 0.2, -0.5, -0.7, 0.1])
    mujoco_robot(model).coordinates.set_state(data, q, np.zeros(model.nq))
    mujoco.mj_kinematics(mj, data)
    for c in model.contacts:
        p = np.asarray(contact_position(model, q, c.name), dtype=float).ravel()
        g = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, c.name)
        np.testing.assert_allclose(data.geom_xpos[g][[0, 2]], p, atol=1e-12)
        assert data.geom_xpos[g][1] == 0.0
        assert mj.geom_size[g][0] == radius
    ground = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    assert data.geom_xpos[ground][2] == -radius


def test_actuators_are_motors_with_the_torque_bounds() -> None:
    model = load_model("five-link")
    mj = mujoco.MjModel.from_xml_string(mjcf_from_model(model))
    joint_actuators = [a for a in model.actuators if a.joint is not None]
    assert mj.nu == len(joint_actuators) == 4  # the ankles are not joints
    for a in joint_actuators:
        i = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_ACTUATOR, a.name)
        assert tuple(mj.actuator_ctrlrange[i]) == a.limits
        assert mj.actuator_gear[i][0] == 1.0
        assert mj.jnt_qposadr[mj.actuator_trnid[i][0]] == model.joint_coordinate(a.joint)
