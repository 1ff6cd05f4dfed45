"""What an MJCF import returns: the model, the map between its coordinates and MuJoCo's, and
the import's notes (:func:`gaitopt.robot.mjcf.import_mjcf`, which re-exports both classes)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from gaitopt.robot.model import RobotModel

#: The limits of a hinge that is not limited: none, as a URDF continuous joint.
UNLIMITED = (-math.inf, math.inf)


@dataclass(frozen=True)
class CoordinateMap:
    """gaitopt coordinates <-> MuJoCo's: ``q[i] = sign[i] (qpos[qpos_index[i]] -
    qpos0[qpos_index[i]]) + offset[i]`` and ``qd[i] = sign[i] qvel[dof_index[i]]`` (m, rad).

    Every MuJoCo degree of freedom maps to exactly one gaitopt coordinate (``nv`` = the
    model's ``nq``), so :meth:`velocity_matrix` ``P`` is a signed permutation: ``qd = P qvel``,
    ``M = P M_mujoco P^T`` and ``bias = P qfrc_bias``.
    """

    names: tuple[str, ...]           # the MuJoCo joint of each gaitopt coordinate
    qpos_index: tuple[int, ...]
    dof_index: tuple[int, ...]
    sign: tuple[float, ...]
    offset: tuple[float, ...]
    qpos0: tuple[float, ...]         # MuJoCo's whole reference configuration

    def q_from_qpos(self, qpos: Sequence[float]) -> NDArray[np.float64]:
        qp, q0 = np.asarray(qpos, dtype=float), np.asarray(self.qpos0)
        idx = list(self.qpos_index)
        return np.asarray(self.sign) * (qp[idx] - q0[idx]) + np.asarray(self.offset)

    def qpos_from_q(self, q: Sequence[float]) -> NDArray[np.float64]:
        qpos = np.array(self.qpos0, dtype=float)
        qpos[list(self.qpos_index)] += np.asarray(self.sign) * (
            np.asarray(q, dtype=float) - np.asarray(self.offset))
        return qpos

    def velocity_matrix(self) -> NDArray[np.float64]:
        """``P`` (nq x nv, entries 0 and +-1) with ``qd = P qvel``."""
        p = np.zeros((len(self.sign), len(self.sign)))
        p[np.arange(len(self.sign)), list(self.dof_index)] = self.sign
        return p

    def qd_from_qvel(self, qvel: Sequence[float]) -> NDArray[np.float64]:
        return self.velocity_matrix() @ np.asarray(qvel, dtype=float)

    def qvel_from_qd(self, qd: Sequence[float]) -> NDArray[np.float64]:
        return self.velocity_matrix().T @ np.asarray(qd, dtype=float)


@dataclass(frozen=True)
class MjcfImport:
    """An imported model, how its coordinates map to MuJoCo's, what was dropped, and the lines
    the import prints (``notes``: base, actuators, contacts, armature, damping, ...).
    ``armature[i]`` (kg m^2 or kg) is MuJoCo's rotor inertia on gaitopt coordinate i, dropped:
    MuJoCo's mass matrix is ``P^T (M + diag(armature)) P``."""

    model: RobotModel
    coordinates: CoordinateMap
    armature: tuple[float, ...]
    notes: tuple[str, ...]
