"""The step's parameters, shared by both formulations: the step length ``L`` (m), the speed
``v`` (m/s), the liftoff impulse ``P`` (N s) and, for free phase shares, the fractions after
them; their bounds for a variant, their scales, the step-time row, and the relaxation of the
unilateral contact conditions that the continuation's first stage solves with.

Both formulations' parameter vectors begin ``p = [L, v, P]`` (:data:`STEP_LENGTH_INDEX` ...);
the staged solve (:mod:`gaitopt.gait.solve.staged`) holds and frees them by these names.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import casadi as ca

from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import ModelScale
from gaitopt.ocp.bounds import Bounds
from gaitopt.ocp.problem import BoundaryConstraint, Parameter

STEP_LENGTH, SPEED, IMPULSE = "step_length", "speed", "impulse"
#: What the stage ``phase fractions free`` frees: the free phase fractions of the full
#: formulation (its parameters ``fraction_<phase>``,
#: :func:`gaitopt.gait.sequence.phase_fractions.fraction_parameters`; bounded there, not here).
FRACTION = "phase fractions"
PARAMETERS = (STEP_LENGTH, SPEED, IMPULSE)
#: Where the step length ``L`` (m), the speed ``v`` (m/s) and the liftoff impulse ``P``
#: (N s) are in the parameter vector ``p`` (the full formulation's begins the same).
STEP_LENGTH_INDEX, SPEED_INDEX, IMPULSE_INDEX = range(3)
#: The step time ``L / v`` (s): a row of the NLP when a step time is given, bounded by
#: :func:`with_step_time`, so problems with
#: different step times share one NLP. Problems without a step time have no such row: even
#: a free row changes IPOPT's path (a warm start in a speed sweep took 353 iterations instead
#: of 79 with it).
STEP_TIME = "step time L / v"

def step_time_row() -> BoundaryConstraint:
    """:data:`STEP_TIME`: the row ``L / v`` (s), free here (bounded by
    :func:`with_step_time`)."""
    return BoundaryConstraint(STEP_TIME, lambda ends, p: p[STEP_LENGTH_INDEX] / p[SPEED_INDEX],
                              lower=-ca.inf, upper=ca.inf, scale=1.0)


def parameter_bounds(options: GaitOptions) -> dict[str, tuple[float, float]]:
    """Bounds of ``L, v, P`` for a variant: a given value becomes equal bounds. (Free phase
    fractions keep the bounds their parameters have in the problem.)"""
    if options.step_length is not None:
        step = (options.step_length, options.step_length)
    elif options.step_time is not None and options.speed is not None:
        implied = options.step_time * options.speed
        step = (implied, implied)
    else:
        step = options.step_length_bounds
    speed = options.speed_bounds if options.speed is None else (options.speed, options.speed)
    # Without double support the trailing leg leaves at the heel strike with no impulse.
    with_impulse = options.impulse and options.double_support
    impulse = (0.0, options.max_impulse) if with_impulse else (0.0, 0.0)
    return {STEP_LENGTH: step, SPEED: speed, IMPULSE: impulse}


#: Scales of the parameters on the reference biped: step length (m), speed (m/s), liftoff
#: impulse (N s); carried over as a length, a speed and an impulse
#: (:mod:`gaitopt.gait.options.model_scale`).
STEP_LENGTH_SCALE, SPEED_SCALE, IMPULSE_SCALE = 0.5, 1.0, 5.0


def parameters_of(bounds: Mapping[str, tuple[float, float]], scale: ModelScale
                  ) -> list[Parameter]:
    """The step length, speed and impulse parameters within ``bounds``, scaled for the model
    of ``scale`` (:data:`STEP_LENGTH_SCALE`, :data:`SPEED_SCALE`, :data:`IMPULSE_SCALE`)."""
    return [Parameter(STEP_LENGTH, *bounds[STEP_LENGTH],
                      scale=scale.length(STEP_LENGTH_SCALE)),
            Parameter(SPEED, *bounds[SPEED], scale=scale.speed(SPEED_SCALE)),
            Parameter(IMPULSE, *bounds[IMPULSE], scale=scale.impulse(IMPULSE_SCALE))]


@dataclass(frozen=True)
class Relaxation:
    """How far the unilateral contact conditions may be violated (N, N s): 0 enforces them.

    The continuation solves a relaxed problem first (the paper's two-stage process). The
    relaxation is applied through the bounds of those rows (:func:`relaxed_bounds`), so
    the relaxed and the enforced problem share one NLP."""

    force: float = 0.0
    impulse: float = 0.0


def with_step_time(bounds: Bounds, options: GaitOptions) -> Bounds:
    """``bounds`` with the step-time row fixed to ``options.step_time`` (s), if given."""
    if options.step_time is None:
        return bounds
    return bounds.with_constraint(STEP_TIME, options.step_time, options.step_time)
