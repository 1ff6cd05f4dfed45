"""What the records of both formulations share (:mod:`gaitopt.gait.record_reduced`,
:mod:`gaitopt.gait.record_full`): the parts a formulation extracts, the sample rate, and the
named points of the dense samples with their positions."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import casadi as ca

from gaitopt.dynamics.kinematics import point_position
from gaitopt.gait.gait_file import GaitEvent, GaitPhase, GaitSamples
from gaitopt.robot.model import RobotModel


@dataclass(frozen=True)
class RecordParts:
    """What a formulation extracts from a solution for its gait record
    (:meth:`gaitopt.gait.formulation.Formulation.record`)."""

    phases: tuple[GaitPhase, ...]
    events: tuple[GaitEvent, ...]
    samples: GaitSamples


#: Samples per second of step time in the dense grid (at least 101 samples per step).
SAMPLE_RATE = 200.0


def sample_points(model: RobotModel) -> tuple[tuple[str, str, tuple[float, float]], ...]:
    """The named points of the gait samples: ``(name, link, point in the link frame)``.

    ``hip`` (the base origin), the origin of every link not attached to the base at its
    origin, named after its joint (``knee_1``, ``ankle_1``, ...), every contact point
    (``tip_1``, ``heel_1``, ...) and ``torso_top`` (the base link's far end), in that order.
    For the five-link biped: hip, knee_1, knee_2, tip_1, tip_2, torso_top."""
    base = model.base
    out = [("hip", base.name, (0.0, 0.0))]
    for link in model.links[1:]:
        if link.joint is None or (link.parent == base.name and
                                  tuple(link.joint.at) == (0.0, 0.0)):
            continue
        out.append((link.joint.name, link.name, (0.0, 0.0)))
    for c in model.contacts:
        x, y = model.link(c.link).local_point(*c.at)
        out.append((c.name, c.link, (float(x), float(y))))
    x, y = base.local_point(base.length)
    out.append(("torso_top", base.name, (float(x), float(y))))
    return tuple(out)


def point_names(model: RobotModel) -> tuple[str, ...]:
    """The names of :func:`sample_points`."""
    return tuple(name for name, _, _ in sample_points(model))


@functools.lru_cache(maxsize=8)
def points_function(model: RobotModel) -> ca.Function:
    """``q -> (2, P)`` world positions of :func:`sample_points`."""
    q = ca.SX.sym("q", model.nq)
    cols = [point_position(model, q, link, p) for _, link, p in sample_points(model)]
    return ca.Function("record_points", [q], [ca.horzcat(*cols)])
