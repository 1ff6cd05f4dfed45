"""The model as a tree of one-degree-of-freedom bodies, one per generalized coordinate.

The floating base becomes three 1-dof joints in series from the world: a prismatic joint along
world x (coordinate ``x``), a prismatic joint along world y (``y``) and a revolute joint
(the base angle), with two massless intermediate bodies. Body ``k`` moves with coordinate
``q[k]``, so body indices equal coordinate indices; link ``i`` is body
``model.coordinate_of_link(i)`` (2 for the base, ``2 + i`` for the others).

Frames: the two intermediate bodies' frames are world-aligned and sit at the base origin (the
point ``(x, y)``), so the transforms between them and to the base frame are the identity and a
pure rotation by the base angle. The transform from the world to the first of them is a pure
translation; it is never needed because the world's velocity is zero and its acceleration
(``-gravity``, no angular part) is the same at every point. Positions use
:func:`gaitopt.dynamics.kinematics.link_poses`, which places the base at ``(x, y)``.

The joint of a link ``i >= 1`` sits at ``offset`` (its parent's frame, metres) and rotates the
link by ``q[2 + i]`` relative to its parent.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from gaitopt.dynamics.backend import Scalar, cos, sin
from gaitopt.dynamics.spatial import (
    IDENTITY,
    ZERO_INERTIA,
    RigidInertia,
    Transform,
    rigid_inertia,
    transform,
)
from gaitopt.robot.model import RobotModel

#: ``Body.axis`` values: the motion subspace is the unit motion vector along this axis.
ROTATION, TRANSLATION_X, TRANSLATION_Y = 0, 1, 2


@dataclass(frozen=True)
class Body:
    """One 1-dof body. ``parent`` is a body index (-1 for the world); ``axis`` the joint's
    motion subspace (``ROTATION``, ``TRANSLATION_X``, ``TRANSLATION_Y``); ``offset`` the joint
    position in the parent's frame (m); ``link`` the model link index, or ``None``."""

    parent: int
    axis: int
    offset: tuple[float, float]
    inertia: RigidInertia
    link: int | None


def bodies(model: RobotModel) -> tuple[Body, ...]:
    """The bodies of ``model``; ``len(result) == model.nq``."""
    base = model.base
    out = [
        Body(-1, TRANSLATION_X, (0.0, 0.0), ZERO_INERTIA, None),
        Body(0, TRANSLATION_Y, (0.0, 0.0), ZERO_INERTIA, None),
        Body(1, ROTATION, (0.0, 0.0), rigid_inertia(base.mass, base.com_local, base.inertia), 0),
    ]
    for i, link in enumerate(model.links[1:], start=1):
        p = model.parent_index(i)
        assert link.joint is not None  # guaranteed by the loader for non-base links
        offset = model.links[p].local_point(*link.joint.at)
        out.append(Body(model.coordinate_of_link(p), ROTATION, offset,
                        rigid_inertia(link.mass, link.com_local, link.inertia), i))
    return tuple(out)


def joint_transforms(tree: Sequence[Body], q: Sequence[Scalar]) -> list[Transform]:
    """``X_k``: the transform from body ``k``'s parent frame to its own frame, per body."""
    out: list[Transform] = []
    for k, body in enumerate(tree):
        if body.axis == ROTATION:
            out.append(transform(cos(q[k]), sin(q[k]), body.offset[0], body.offset[1]))
        else:
            out.append(IDENTITY)
    return out


def link_index(model: RobotModel, link: str | int) -> int:
    """The index of a link given by name or index, with a clear error."""
    if isinstance(link, str):
        return model.link_index(link)
    if isinstance(link, int) and not isinstance(link, bool) and 0 <= link < len(model.links):
        return link
    raise ValueError(f"link must be a link name or an index in 0..{len(model.links) - 1} of "
                     f"model {model.name!r}, got {link!r}")


def contact_names(model: RobotModel, contacts: Sequence[str] | str, what: str = "contacts"
                  ) -> tuple[str, ...]:
    """Validate a sequence of distinct contact names of ``model``."""
    if isinstance(contacts, str):
        contacts = (contacts,)
    known = [c.name for c in model.contacts]
    out = tuple(contacts)
    for name in out:
        if name not in known:
            raise ValueError(f"{what}: model {model.name!r} has no contact point {name!r} "
                             f"(known: {', '.join(known) or 'none'})")
    if len(set(out)) != len(out):
        raise ValueError(f"{what}: contact names must be distinct, got {list(out)}")
    return out


#: How a held contact point may be held: ``"xy"`` pins it (both world axes), ``"y"`` holds it
#: along the ground normal only (it may not move vertically but may slide; the second point of
#: a flat foot whose first point is pinned, so that the constraints stay independent).
HOLD_AXES: dict[str, tuple[int, ...]] = {"xy": (0, 1), "y": (1,)}


@dataclass(frozen=True)
class Hold:
    """A contact point held on the ground along some world axes (indices into its position
    ``(x, y)``): the rows of the constraint ``p_c(q)[axes] = const``."""

    name: str
    axes: tuple[int, ...] = (0, 1)

    @property
    def spec(self) -> str:
        """The text form: ``name`` for a pin, ``name:y`` for a normal-only hold."""
        return self.name if self.axes == (0, 1) else f"{self.name}:y"


def hold_name(spec: str) -> str:
    """The contact name of a hold spec (``"toe_1:y"`` -> ``"toe_1"``)."""
    return spec.split(":", 1)[0]


def holds(model: RobotModel, specs: Sequence[str] | str, what: str = "contacts"
          ) -> tuple[Hold, ...]:
    """Parse hold specs: ``"name"`` or ``"name:xy"`` (pinned) and ``"name:y"`` (held along
    the normal only). Names are validated like :func:`contact_names`."""
    if isinstance(specs, str):
        specs = (specs,)
    out = []
    for spec in specs:
        name, _, axes = spec.partition(":")
        if axes and axes not in HOLD_AXES:
            raise ValueError(f"{what}: hold {spec!r}: the axes after ':' must be one of "
                             f"{', '.join(HOLD_AXES)}")
        out.append(Hold(name, HOLD_AXES[axes or "xy"]))
    contact_names(model, [h.name for h in out], what)
    return tuple(out)


def hold_specs(model: RobotModel, specs: Sequence[str] | str, what: str = "contacts"
               ) -> tuple[str, ...]:
    """Validated, normalised hold specs (``"name:xy"`` -> ``"name"``)."""
    return tuple(h.spec for h in holds(model, specs, what))


def hold_rows(model: RobotModel, specs: Sequence[str]) -> int:
    """Number of constraint rows of the held points ``specs`` (2 per pin, 1 per normal-only
    hold)."""
    return sum(len(h.axes) for h in holds(model, specs))


def contact_point(model: RobotModel, name: str) -> tuple[int, tuple[float, float]]:
    """``(link index, point in the link frame)`` of a contact point."""
    contact_names(model, (name,), "contact")
    c = model.contact(name)
    i = model.link_index(c.link)
    return i, model.links[i].local_point(*c.at)
