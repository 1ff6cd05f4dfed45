"""The built-in contact sequences, each an instance of the one mechanism of
:mod:`gaitopt.gait.sequence.contact_sequence` (whose docstring describes them): the paper's walk and
the single-support walk (:func:`walking_sequence`), a run (:func:`running_sequence`) and a walk
on feet with heel and toe points (:func:`heel_toe_sequence`). Leg 1 is the model's first
contact point (its first foot's rear point for the heel-toe walk), anchored at ``x = 0``; leg 2
lands one step length ahead (anchor 1).
"""

from __future__ import annotations

from collections.abc import Mapping

from gaitopt.dynamics.kinematics import contact_position
from gaitopt.gait.sequence.contact_sequence import (
    ContactSequence,
    ContactSequenceError,
    EventSpec,
    PhaseSpec,
)
from gaitopt.gait.sequence.knots import BUILTIN_PHASES
from gaitopt.robot.model import RobotModel


def walking_sequence(model: RobotModel, single_support_fraction: float, *,
                     impulse: bool) -> ContactSequence:
    """The paper's walk (``single_support_fraction < 1``) or the single-support walk (``= 1``)
    on the model's first two contact points (leg 1, leg 2)."""
    c1, c2 = _two_contacts(model)
    anchors = ((c1, 0.0), (c2, 1.0))
    if single_support_fraction >= 1.0:
        return ContactSequence(
            "walk-single-support",
            (PhaseSpec(BUILTIN_PHASES["walk-single-support"][0], (c1,), 1.0),),
            (EventSpec("heel_strike", touchdown=(c2,), release=(c1,)),),
            anchors)
    f = single_support_fraction
    single, double = BUILTIN_PHASES["walk"]
    return ContactSequence(
        "walk",
        (PhaseSpec(single, (c1,), f), PhaseSpec(double, (c1, c2), 1.0 - f)),
        (EventSpec("heel_strike", touchdown=(c2,)),
         EventSpec("liftoff", release=(c1,), impulse=impulse)),
        anchors)


def running_sequence(model: RobotModel, stance_fraction: float) -> ContactSequence:
    """A run: stance on leg 1 for ``stance_fraction`` of the step, then flight; leg 2 lands
    one step length ahead. On feet with a heel and a toe point (:func:`run_points`) the run
    is on the toes (a forefoot run: the toe pinned, the heel above the ground)."""
    c1, c2 = run_points(model)
    f = stance_fraction
    stance, flight = BUILTIN_PHASES["run"]
    return ContactSequence(
        "run",
        (PhaseSpec(stance, (c1,), f), PhaseSpec(flight, (), 1.0 - f)),
        (EventSpec("toe_off", release=(c1,)), EventSpec("touchdown", touchdown=(c2,))),
        ((c1, 0.0), (c2, 1.0)))


def legs_contacts(model: RobotModel) -> tuple[tuple[str, ...], ...]:
    """The contact points of each leg: grouped by the first link below the base on the chain
    from the base to each contact (a contact on the base is a group of its own), legs in the
    order of their first contact point."""
    groups: dict[str, list[str]] = {}
    for c in model.contacts:
        chain = model.chain(model.link_index(c.link))
        root = model.links[chain[1]].name if len(chain) > 1 else model.base.name
        groups.setdefault(root, []).append(c.name)
    return tuple(tuple(g) for g in groups.values())


def run_points(model: RobotModel) -> tuple[str, str]:
    """The points a run stands on: the model's first two contact points, or, on two feet with
    two points each (heel and toe), the front one of each foot in the standing pose (all
    coordinates 0)."""
    legs = legs_contacts(model)
    if len(legs) != 2 or [len(g) for g in legs] != [2, 2]:
        return _two_contacts(model)
    zero = [0.0] * model.nq
    return tuple(max(g, key=lambda c: float(contact_position(model, zero, c)[0]))  # type: ignore[return-value]
                 for g in legs)


def feet(model: RobotModel, contact_swap: Mapping[str, str]
         ) -> tuple[tuple[str, str], tuple[str, str]]:
    """``((heel_1, toe_1), (heel_2, toe_2))``: the two contact points on the link of the
    model's first contact (its foot), rear one first in the standing pose (all coordinates
    0), and their counterparts on the other foot by the leg swap."""

    link = model.contacts[0].link
    on_foot = [c.name for c in model.contacts if c.link == link]
    if len(on_foot) != 2:
        raise ContactSequenceError(
            f"model {model.name!r}: a heel-toe gait needs exactly two contact points on the "
            f"foot {link!r} (heel and toe); it has {len(on_foot)}")
    zero = [0.0] * model.nq
    heel, toe = sorted(on_foot, key=lambda c: float(contact_position(model, zero, c)[0]))
    other = (contact_swap.get(heel, heel), contact_swap.get(toe, toe))
    if other[0] == heel or other[1] == toe:
        raise ContactSequenceError(f"model {model.name!r}: the leg swap maps the foot "
                                   f"points {heel!r}, {toe!r} to themselves")
    return (heel, toe), other


def foot_length(model: RobotModel, heel: str, toe: str) -> float:
    """Distance (m) from the heel point to the toe point (on one link)."""
    a, b = model.contact(heel).at, model.contact(toe).at
    return float(((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2) ** 0.5)


def heel_toe_sequence(model: RobotModel, contact_swap: Mapping[str, str],
                      single_support_fraction: float, *, impulse: bool) -> ContactSequence:
    """A walk with feet (module docstring): heel 1 pinned at ``x = 0`` and its toe held
    normal-only while foot 1 is flat; toe 1 pinned at ``x = d`` (``d`` the foot length) once
    the heel rises; heel 2 strikes at ``x = L``; toe 1 leaves (with the liftoff impulse when
    ``impulse``); foot 2 rolls on its heel until its toe strikes. Shares of the step time:
    double support ``1 - f``; of the single support ``f``: foot flat 0.5, heel off 0.35, heel
    rocker 0.15."""
    (h1, t1), (h2, t2) = feet(model, contact_swap)
    f = single_support_fraction
    if f >= 1.0:
        raise ContactSequenceError("the heel-toe gait has a double support: "
                                   "single_support_fraction must be < 1")
    flat, heel_off, double, rocker = BUILTIN_PHASES["heel-toe"]
    return ContactSequence(
        "heel-toe",
        (PhaseSpec(flat, (h1, f"{t1}:y"), 0.5 * f),
         PhaseSpec(heel_off, (t1,), 0.35 * f),
         PhaseSpec(double, (t1, h2), 1.0 - f),
         PhaseSpec(rocker, (h2,), 0.15 * f)),
        (EventSpec("heel_rise", release=(h1,)),
         EventSpec("heel_strike", touchdown=(h2,)),
         EventSpec("toe_off", release=(t1,), impulse=impulse),
         EventSpec("foot_flat", touchdown=(t2,))),
        ((h1, 0.0), (t1, 0.0), (h2, 1.0)),
        ((t1, foot_length(model, h1, t1)),))


def _two_contacts(model: RobotModel) -> tuple[str, str]:
    if len(model.contacts) < 2:
        raise ContactSequenceError(
            f"model {model.name!r}: a walking sequence needs two contact points (one per "
            f"leg); it has {len(model.contacts)}")
    return model.contacts[0].name, model.contacts[1].name
