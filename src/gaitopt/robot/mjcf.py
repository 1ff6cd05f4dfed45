"""MJCF import through MuJoCo's own compiler: a planar MuJoCo model -> a :class:`RobotModel`.

The file is compiled by MuJoCo (``mujoco.MjModel.from_xml_path``); nothing is parsed by hand,
so defaults, classes, ``inertiafromgeom``, ``ref`` and includes mean what MuJoCo says. The
import reads the compiled arrays and MuJoCo's own forward kinematics at the reference
configuration ``qpos0`` (``mj_kinematics``: ``xanchor``, ``xaxis``, ``xipos``, ``ximat``).

Frames (``docs/mjcf.md``). MuJoCo's world is x forward, y left, z up, like URDF's; with the
common joint axis ``y`` (the default), gaitopt (x, y, z) = MuJoCo (x, z, -y), so a hinge about
MuJoCo -y turns the child counter-clockwise in gaitopt's sense and one about +y (Walker2d's
``rooty``) turns it by ``-(qpos - qpos0)``. At ``qpos0`` every gaitopt joint angle and the
base angle are 0 and every gaitopt link frame is parallel to the world.

* The **floating base** is the first body with joints below the world: it must carry two
  slide joints along the plane's x and up axes and then a hinge about the normal (Walker2d:
  ``rootx, rootz, rooty``; dm_control's walker: ``rootz, rootx, rooty``). Its gaitopt origin
  is the hinge's anchor.
* Every other body with one hinge starts a gaitopt link named after the body, with its origin
  at the hinge's anchor (``jnt_pos``: a joint may sit away from its body's origin); a body
  without joints is welded to its parent and merges into its parent's link (masses add; the
  parallel-axis theorem in the plane).
* Mass, centre of mass and inertia: ``body_mass``, ``xipos`` and the component about the
  normal n of ``ximat diag(body_inertia) ximat^T`` (so ``body_ipos``, ``body_iquat`` and what
  MuJoCo computed from geoms). Points off the plane (dm_control's legs at y = +-0.05) are
  projected into it; for motion in the plane this is exact.
* Actuators: one per motor on a hinge, in MuJoCo's order, torque bounds
  ``sign gear gainprm[0] ctrlrange`` (intersected with ``gear forcerange``): u = gear ctrl.
* Contact points: ``--contact`` points, else heels and toes inferred from the leaf links'
  geoms (:mod:`gaitopt.robot.mjcf_contacts`, :mod:`gaitopt.robot.contact_inference`).
* Coordinates: gaitopt ``q[i] = sign_i (qpos[a_i] - qpos0[a_i]) + offset_i`` and
  ``qd[i] = sign_i qvel[d_i]`` (:class:`CoordinateMap`); the offsets are the base origin's
  world position at ``qpos0``.

What gaitopt models have no place for is dropped and reported in :attr:`MjcfImport.notes`:
joint ``armature`` (a rotor inertia that MuJoCo adds to the diagonal of the mass matrix),
damping, friction loss and stiffness.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from gaitopt.robot.errors import ModelError
from gaitopt.robot.mjcf_build import Builder
from gaitopt.robot.mjcf_result import CoordinateMap as CoordinateMap
from gaitopt.robot.mjcf_result import MjcfImport as MjcfImport
from gaitopt.robot.model import RobotModel
from gaitopt.robot.urdf import ContactSpec
from gaitopt.robot.urdf_plane import IN_PLANE, PLANE

__all__ = ["CoordinateMap", "MjcfImport", "import_mjcf", "is_mjcf", "model_from_mjcf"]

#: The start of an MJCF file: an XML declaration and comments, then ``<mujoco``.
_MJCF_START = re.compile(r"\A(?:\ufeff)?\s*(?:<\?.*?\?>\s*|<!--.*?-->\s*)*<mujoco\b", re.S)
INSTALL_HINT = "pip install 'gaitopt[mujoco]'"


def _mujoco(label: str) -> Any:
    """The ``mujoco`` module, imported on first use."""
    try:
        import mujoco
    except ImportError:
        raise ModelError(label, "", label, f"MuJoCo installed ({INSTALL_HINT})",
                         problem="reading MJCF needs the mujoco package, which is not "
                                 "installed") from None
    return mujoco


def is_mjcf(path: str | os.PathLike[str]) -> bool:
    """Whether a file is MJCF: its root element is ``<mujoco`` (after an XML declaration and
    comments), or it is empty or cannot be read and its name ends in ``.xml``."""
    try:
        with open(path, "rb") as f:
            head = f.read(4096).decode("utf-8", "replace")
    except OSError:
        head = ""
    if _MJCF_START.match(head) is not None:
        return True
    return not head.strip() and os.fspath(path).lower().endswith(".xml")


def model_from_mjcf(source: str | os.PathLike[str], *, contacts: Iterable[ContactSpec] = (),
                    axis: str = "y", name: str | None = None) -> RobotModel:
    """The model of :func:`import_mjcf`."""
    return import_mjcf(source, contacts=contacts, axis=axis, name=name).model


def import_mjcf(source: str | os.PathLike[str], *, contacts: Iterable[ContactSpec] = (),
                axis: str = "y", name: str | None = None) -> MjcfImport:
    """Compile an MJCF file (or MJCF text starting with ``<``) with MuJoCo and read the planar
    robot in it (see the module docstring).

    Args:
        source: a path, or MJCF text (includes then resolve against the working directory).
        contacts: contact points ``NAME=BODY:X,Z`` in a MuJoCo body's frame (X, Z in m; Y, Z
            with ``axis="x"``); when given, they replace the points inferred from foot geoms.
        axis: the common hinge axis, ``"y"`` (plane MuJoCo x-z) or ``"x"`` (plane y-z).
        name: the model name (default: the MJCF model's name).

    Raises:
        ModelError: one line naming the file, the joint, body or actuator and what is allowed.
    """
    text = isinstance(source, str) and source.lstrip().startswith("<")
    label = "<string>" if text else os.fspath(source)
    if axis not in PLANE:
        raise ModelError(label, "axis", axis, "y or x (the common hinge axis)")
    mujoco = _mujoco(label)
    try:
        m = (mujoco.MjModel.from_xml_string(source) if text
             else mujoco.MjModel.from_xml_path(os.fspath(Path(label))))
    except (ValueError, OSError) as exc:
        detail = " ".join(str(exc).split()) or type(exc).__name__
        raise ModelError(label, "", label, "an MJCF file that MuJoCo compiles",
                         problem=f"MuJoCo cannot compile it: {detail}") from None
    return Builder(mujoco, m, label, PLANE[axis], IN_PLANE[axis], axis).build(
        list(contacts), name)
