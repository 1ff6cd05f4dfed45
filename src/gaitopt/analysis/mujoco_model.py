"""A gaitopt model in MuJoCo: the compiled MJCF, the map between MuJoCo's ``qpos``/``qvel`` and
gaitopt's ``q``/``qd``, the contact geoms and the joint servos (``docs/simulate.md``).

The MJCF is gaitopt's export (:func:`gaitopt.robot.mjcf_export.mjcf_from_model`) or a file
(``--mjcf FILE``, e.g. the file the model was imported from), matched to the model **by
name**: the base body is named after the base link and carries three root joints, slides
along +-x and +-z and a hinge about +-y (in any order); every gaitopt joint is a hinge of the
same name about +-y; every link that carries a contact point is a body of the same name; a
contact point is a geom of the same name if the file has one (gaitopt's export does), else
the file's own geoms touch the ground and the point's touchdown is read from its height
(:mod:`.simulate`). With ``s`` the sign of
each coordinate (+1 for a slide along +x or +z and for a hinge about -y; -1 otherwise) and
``p0`` the base body's position (MuJoCo x, z), ``q[i] = s[i] qpos[index[i]] (+ p0 on x, y)``
and ``qd[i] = s[i] qvel[dof[i]]`` (:class:`CoordinateMap`). MuJoCo orders its coordinates
depth-first along the body tree, gaitopt in the order of the model's links; the map handles
both.

MuJoCo is imported lazily: without it, :func:`import_mujoco` raises a one-line error that
says ``pip install gaitopt[mujoco]``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gaitopt.robot.mjcf_export import MjcfContact, mjcf_from_model
from gaitopt.robot.model import BASE_ANGLE, BASE_X, BASE_Y, RobotModel

Array = NDArray[np.float64]


class MujocoModelError(ValueError):
    """MuJoCo is missing, or an MJCF file does not match the gait's model."""


def import_mujoco() -> Any:
    """The ``mujoco`` module, or :class:`MujocoModelError` with the install hint."""
    try:
        import mujoco
    except ImportError:
        raise MujocoModelError("MuJoCo is not installed: pip install gaitopt[mujoco]") from None
    return mujoco


@dataclass(frozen=True, eq=False)
class CoordinateMap:
    """gaitopt ``q`` (nq,) from MuJoCo's state: ``q = sign * qpos[index] + offset``,
    ``qd = sign * qvel[dof]``; ``offset`` (nq,) is the base body's position on x, y."""

    index: NDArray[np.intp]
    dof: NDArray[np.intp]
    sign: Array
    offset: Array

    def q(self, qpos: Array) -> Array:
        return self.sign * np.asarray(qpos)[self.index] + self.offset

    def qd(self, qvel: Array) -> Array:
        return self.sign * np.asarray(qvel)[self.dof]

    def set_state(self, data: Any, q: Array, qd: Array) -> None:
        """Write gaitopt's ``q``, ``qd`` into MuJoCo's ``data.qpos``, ``data.qvel``."""
        data.qpos[self.index] = self.sign * (np.asarray(q) - self.offset)
        data.qvel[self.dof] = self.sign * np.asarray(qd)


@dataclass(frozen=True, eq=False)
class MujocoRobot:
    """The compiled MuJoCo model of a gaitopt ``model``: ``mj`` (``MjModel``), the
    coordinate map, the geom id of each contact point that has a geom of its name (a file's
    own feet may have none), the body of each contact point's link, the actuator id and sign
    of each joint actuator (gaitopt actuator index -> (MuJoCo actuator, gear * sign)), the
    MJCF text and where it came from."""

    model: RobotModel
    mj: Any
    coordinates: CoordinateMap
    contact_geoms: dict[str, int]
    contact_bodies: dict[str, int]
    ground_geoms: frozenset[int]
    joint_actuators: dict[int, tuple[int, float]]
    source: str
    mjcf: str

    def set_servos(self, kp: float, kd: float, *, bounded: bool = True) -> None:
        """Turn the joint actuators into PD servos with a feed-forward input:
        ``tau = ctrl - kp q - kd qd`` in gaitopt's joint coordinates (ctrl = ``u_ff + kp q_ref
        + kd qd_ref``, :meth:`servo_ctrl`), MuJoCo's affine bias (``biasprm = (0, -kp/g^2,
        -kd/g^2)`` for the transmission's gear times sign ``g``), so the ``implicitfast``
        integrator treats the damping implicitly. ``bounded``: the total torque is clipped
        to the actuator's bounds (``forcerange``)."""
        mj = self.mj
        for j, (act, g) in self.joint_actuators.items():
            mj.actuator_dyntype[act] = 0   # mjDYN_NONE
            mj.actuator_gaintype[act] = 0  # mjGAIN_FIXED
            mj.actuator_biastype[act] = 1  # mjBIAS_AFFINE
            mj.actuator_gainprm[act, :] = 0.0
            mj.actuator_gainprm[act, 0] = 1.0
            mj.actuator_biasprm[act, :] = 0.0
            mj.actuator_biasprm[act, 1] = -kp / g ** 2
            mj.actuator_biasprm[act, 2] = -kd / g ** 2
            mj.actuator_ctrllimited[act] = 0
            lo, hi = sorted(b / g for b in self.model.actuators[j].limits)
            mj.actuator_forcelimited[act] = 1 if bounded else 0
            mj.actuator_forcerange[act] = (lo, hi)

    def servo_ctrl(self, u_ff: Array, q_ref: Array, qd_ref: Array, kp: float,
                   kd: float) -> Array:
        """``ctrl`` (nu_mj,) of the servos for gaitopt torques ``u_ff`` (nu,) N m and joint
        references ``q_ref``, ``qd_ref`` (nq,)."""
        ctrl = np.zeros(self.mj.nu)
        for j, (act, g) in self.joint_actuators.items():
            i = self.model.joint_coordinate(self.model.actuators[j].joint or "")
            ctrl[act] = (u_ff[j] + kp * q_ref[i] + kd * qd_ref[i]) / g
        return ctrl


def _id(mujoco: Any, mj: Any, kind: Any, name: str) -> int:
    return int(mujoco.mj_name2id(mj, kind, name))


def _names(mujoco: Any, mj: Any, kind: Any, count: int) -> str:
    return ", ".join(str(mujoco.mj_id2name(mj, kind, i)) for i in range(count))


def mujoco_robot(model: RobotModel, *, contact: MjcfContact | None = None,
                 mjcf: str | Path | None = None) -> MujocoRobot:
    """Compile ``model`` for MuJoCo: its MJCF export with ``contact`` settings, or the MJCF
    file ``mjcf`` matched by name (module docstring). Raises :class:`MujocoModelError` naming
    what does not match."""
    mujoco = import_mujoco()
    source = "gaitopt's MJCF export"
    if mjcf is None:
        text = mjcf_from_model(model, contact=contact)
        try:
            mj = mujoco.MjModel.from_xml_string(text)
        except ValueError as exc:
            raise MujocoModelError(f"model {model.name!r}: MuJoCo refuses gaitopt's MJCF "
                                   f"export: {' '.join(str(exc).split())}") from None
    else:
        path = Path(mjcf)
        source = str(path)
        try:
            text = path.read_text()
            mj = mujoco.MjModel.from_xml_path(str(path))
        except (OSError, ValueError) as exc:
            raise MujocoModelError(f"--mjcf {path}: {' '.join(str(exc).split())}") from None
    jt, bd, gm = (mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY,
                  mujoco.mjtObj.mjOBJ_GEOM)
    nq = model.nq
    index, dof = np.zeros(nq, dtype=np.intp), np.zeros(nq, dtype=np.intp)
    sign, offset = np.ones(nq), np.zeros(nq)
    base = _id(mujoco, mj, bd, model.base.name)
    if base < 0:
        raise MujocoModelError(f"{source}: no body named {model.base.name!r} (the model's base "
                               f"link); its bodies: {_names(mujoco, mj, bd, mj.nbody)}")
    if not np.allclose(mj.body_quat[base], (1, 0, 0, 0)) or mj.body_parentid[base] != 0:
        raise MujocoModelError(f"{source}: body {model.base.name!r} must be a child of the world "
                               "with no rotation (a planar floating base)")
    root = [j for j in range(mj.njnt) if mj.jnt_bodyid[j] == base]
    found: dict[int, tuple[int, float]] = {}
    for j in root:
        axis = mj.jnt_axis[j]
        kind = int(mj.jnt_type[j])
        if kind == 2 and abs(abs(axis[0]) - 1) < 1e-9:      # mjJNT_SLIDE along x
            found[BASE_X] = (j, float(np.sign(axis[0])))
        elif kind == 2 and abs(abs(axis[2]) - 1) < 1e-9:    # slide along z
            found[BASE_Y] = (j, float(np.sign(axis[2])))
        elif kind == 3 and abs(abs(axis[1]) - 1) < 1e-9:    # mjJNT_HINGE about y
            found[BASE_ANGLE] = (j, -float(np.sign(axis[1])))
    if len(root) != 3 or len(found) != 3:
        raise MujocoModelError(f"{source}: body {model.base.name!r} must carry exactly three root "
                               "joints: slides along x and z and a hinge about y")
    for i, (j, s) in found.items():
        index[i], dof[i], sign[i] = mj.jnt_qposadr[j], mj.jnt_dofadr[j], s
    offset[BASE_X], offset[BASE_Y] = mj.body_pos[base][0], mj.body_pos[base][2]
    for joint in model.joints:
        j = _id(mujoco, mj, jt, joint.name)
        if j < 0 or int(mj.jnt_type[j]) != 3 or abs(abs(mj.jnt_axis[j][1]) - 1) > 1e-9:
            raise MujocoModelError(
                f"{source}: the model's joint {joint.name!r} is not a hinge about +-y of that "
                f"name; its joints: {_names(mujoco, mj, jt, mj.njnt)}")
        i = model.joint_coordinate(joint.name)
        index[i], dof[i] = mj.jnt_qposadr[j], mj.jnt_dofadr[j]
        sign[i] = -float(np.sign(mj.jnt_axis[j][1]))
    if mj.nq != nq or mj.nv != nq:
        raise MujocoModelError(f"{source}: {mj.nq} coordinates, the model has {nq} "
                               f"({', '.join(model.coordinate_names)})")
    geoms, contact_bodies = {}, {}
    for c in model.contacts:
        g = _id(mujoco, mj, gm, c.name)
        if g >= 0:
            geoms[c.name] = g
        body = _id(mujoco, mj, bd, c.link)
        if body < 0:
            raise MujocoModelError(f"{source}: no body named {c.link!r} (the link of the "
                                   f"model's contact point {c.name!r}); its bodies: "
                                   f"{_names(mujoco, mj, bd, mj.nbody)}")
        contact_bodies[c.name] = body
    ground = frozenset(g for g in range(mj.ngeom) if mj.geom_bodyid[g] == 0)
    actuators: dict[int, tuple[int, float]] = {}
    for k, a in enumerate(model.actuators):
        if a.joint is None:
            continue
        j = _id(mujoco, mj, jt, a.joint)
        acts = [m for m in range(mj.nu) if mj.actuator_trnid[m][0] == j
                and int(mj.actuator_trntype[m]) == 0]  # mjTRN_JOINT
        if len(acts) != 1:
            raise MujocoModelError(f"{source}: joint {a.joint!r} needs exactly one actuator "
                                   f"(gaitopt's {a.name!r}), found {len(acts)}")
        i = model.joint_coordinate(a.joint)
        actuators[k] = (acts[0], float(mj.actuator_gear[acts[0]][0]) * sign[i])
    return MujocoRobot(model=model, mj=mj, coordinates=CoordinateMap(index, dof, sign, offset),
                       contact_geoms=geoms, contact_bodies=contact_bodies,
                       ground_geoms=ground, joint_actuators=actuators,
                       source=source, mjcf=text)

