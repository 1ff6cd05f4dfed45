"""What a URDF import assumes where the file is silent, and the lines that say so.

- **Actuators.** A file with any ``<transmission>`` actuates exactly the joints its
  transmissions name (the ROS reading); a file without one actuates every joint with an
  ``effort`` > 0. The torque bounds are ``+-effort``; a transmission joint whose effort is
  missing or 0 gets ``+-`` :func:`default_bound` (the whole weight at the standing height, a
  finite bound: gaitopt's costs, checks and figures scale torques by their bounds) and a
  ``warning:`` line.
- **Symmetry of inferred feet.** Heel and toe points listed heel 1, toe 1, heel 2, toe 2 give
  no inferred symmetry (``docs/conventions.md``), so when the import infers them on two feet
  whose chains from the base pair up link by link, it declares that symmetry.
- **The lines** of ``gaitopt model import``: the floating base, the links merged, the
  actuators, the contacts, the symmetry.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.robot.errors import ModelError
from gaitopt.robot.model import RobotModel
from gaitopt.robot.schema import model_from_dict
from gaitopt.robot.symmetry import SymmetryError, model_symmetry, swap_matrices
from gaitopt.robot.urdf_xml import Reader, UJoint


@dataclass(frozen=True)
class Actuated:
    """A gaitopt joint of the import and its URDF ``effort`` (N m, 0 if none)."""

    joint: str
    effort: float


def default_bound(total_mass: float, height: float, gravity: float) -> float:
    """The torque bound (N m) of a transmission joint without an effort: ``m g h``, the total
    mass ``m`` (kg) times gravity ``g`` (m/s^2) times the standing height ``h`` (m: the depth
    of the model's lowest point below the base origin at the standing pose, 1 m if nothing
    is below it), the torque that holds the whole robot level at arm's length."""
    return total_mass * gravity * (height if height > 0.0 else 1.0)


def actuators_from_urdf(joints: Sequence[Actuated], transmissions: Sequence[tuple[str, str]],
                        default: float, *, reader: Reader,
                        urdf_joints: dict[str, UJoint]) -> tuple[list[dict[str, Any]],
                                                                list[str]]:
    """The actuators (model-file entries, named after their joints, in the order of
    ``joints``) and the lines saying where they came from (module docstring).

    Raises:
        ModelError: a transmission naming a joint that is not a gaitopt joint.
    """
    known = {a.joint for a in joints}
    for joint, _ in transmissions:
        if joint not in known:
            kind = urdf_joints[joint].type if joint in urdf_joints else None
            problem = (f"joint {joint!r} is {kind}" if kind is not None
                       else f"no joint {joint!r}")
            raise reader.fail(f"transmission joint {joint!r}", joint, "a revolute or "
                              "continuous joint below the floating base "
                              f"({', '.join(sorted(known)) or 'none'})", problem=problem)
    if transmissions:
        driven = {j for j, _ in transmissions}
        chosen = [a for a in joints if a.joint in driven]
        source = "the <transmission> elements; efforts of other joints ignored"
    else:
        chosen = [a for a in joints if a.effort > 0.0]
        source = "the joints with an effort > 0; no <transmission> in the file"
    out, bounds, defaulted = [], [], []
    for a in chosen:
        bound = a.effort if a.effort > 0.0 else default
        if a.effort <= 0.0:
            defaulted.append(a.joint)
        out.append({"name": a.joint, "joint": a.joint, "limits": [-bound, bound]})
        bounds.append(f"{a.joint} +-{bound:.4g}")
    lines = [f"actuators: {', '.join(bounds)} N m (from {source})" if bounds else
             f"actuators: none (from {source})"]
    if defaulted:
        lines.append(f"warning: no effort on {', '.join(defaulted)}: torque bound +-"
                     f"{default:.4g} N m (total mass x g x standing height; set <limit "
                     "effort> or edit actuators[].limits)")
    return out, lines


def base_note(base: str, chain: Sequence[UJoint], coordinates: Sequence[str],
              fixed_to_base: Sequence[str]) -> str:
    """The floating-base line: which URDF link is the base, what is fixed to it, and which
    URDF joints (if any) its coordinates ``x, y, angle`` replace."""
    fixed = f" (with {', '.join(fixed_to_base)} fixed to it)" if fixed_to_base else ""
    moving = [j for j in chain if j.type != "fixed"]
    if not moving:
        return (f"floating base: the root link {base!r}{fixed}; its coordinates "
                f"{', '.join(coordinates)}")
    joints = ", ".join(f"{j.name} ({j.type})" for j in moving)
    return (f"floating base: link {base!r}{fixed}; the URDF joints {joints} became its "
            f"coordinates {', '.join(coordinates)}")


def declare_foot_symmetry(data: dict[str, Any], *, source: str) -> None:
    """Declare in ``data`` (a model-file dict) the symmetry of inferred feet: contacts
    ``heel_1, toe_1`` and ``heel_2, toe_2`` on two links whose chains from the base have the
    same length and no link in common pair link by link. Nothing if they do not, or if the
    pairs do not map the model onto itself."""
    names = [c["name"] for c in data["contacts"]]
    if names != ["heel_1", "toe_1", "heel_2", "toe_2"]:
        return
    parent = {link["name"]: link["parent"] for link in data["links"]}

    def chain(link: str) -> list[str]:
        out = []
        while parent[link] is not None:
            out.append(link)
            link = parent[link]
        return out[::-1]

    feet = [chain(data["contacts"][0]["link"]), chain(data["contacts"][2]["link"])]
    if len(feet[0]) != len(feet[1]) or set(feet[0]) & set(feet[1]) or not feet[0]:
        return
    data["symmetry"] = {"links": [list(p) for p in zip(*feet, strict=True)],
                        "contacts": [["heel_1", "heel_2"], ["toe_1", "toe_2"]]}
    try:
        model_from_dict(data, source=source)
    except ModelError:
        del data["symmetry"]


def symmetry_note(model: RobotModel, *, by_import: bool = False) -> str:
    """The symmetry line: the pairs and whether declared (in the file, or ``by_import`` for
    inferred feet) or inferred, or that there is none (the import does not fail for that; a
    periodic gait needs one)."""
    try:
        symmetry = model_symmetry(model)
        swap_matrices(model)
    except SymmetryError as exc:
        if len(model.contacts) < 2:
            return f"symmetry: none ({exc})"
        return (f"symmetry: none: the legs are not mirror images ({exc}); a periodic gait "
                "needs one")
    if by_import:
        pairs = ", ".join(f"{a} <-> {b}" for a, b in symmetry.links + symmetry.contacts)
        return f"symmetry: {pairs} (declared by the import: the chains to the inferred feet)"
    return f"symmetry: {symmetry.describe()}"


__all__ = ["Actuated", "actuators_from_urdf", "base_note", "declare_foot_symmetry",
           "default_bound", "symmetry_note"]
