"""The decision parameters of the full formulation and the phase times they give.

``p = [L, v, P, fraction_<phase> ...]``: the step length ``L`` (m), the speed ``v`` (m/s) and
the liftoff impulse ``P`` (N s), as in the reduced formulation
(:func:`gaitopt.gait.formulations.step_parameters.parameters_of`), then one share of the step
time (1) per free phase but the last free one
(:func:`gaitopt.gait.sequence.phase_fractions.fraction_parameters`). Phase ``i`` lasts
``s_i steps L / v`` (s), ``s_i`` its share: the period is a step, or the stride of
``seq.steps = 2`` steps.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca

from gaitopt.gait.formulations.step_parameters import (
    IMPULSE,
    IMPULSE_INDEX,
    SPEED_INDEX,
    STEP_LENGTH_INDEX,
    parameter_bounds,
    parameters_of,
)
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.sequence.contact_sequence import ContactSequence
from gaitopt.gait.sequence.phase_fractions import fraction_parameters, phase_share
from gaitopt.ocp.problem import Parameter
from gaitopt.robot.model import RobotModel

#: Index in ``p`` of the first free phase fraction (after ``L, v, P``).
FRACTION_INDEX = 3
_L, _V, _P, _F = STEP_LENGTH_INDEX, SPEED_INDEX, IMPULSE_INDEX, FRACTION_INDEX


def full_parameters(model: RobotModel, options: GaitOptions, seq: ContactSequence
                    ) -> list[Parameter]:
    """``L, v, P`` within :func:`~gaitopt.gait.formulations.step_parameters.parameter_bounds`
    (``P`` fixed to 0 N s when no event of ``seq`` has a liftoff impulse), scaled for
    ``model``, then the free phase fractions within their bounds (scale 1)."""
    bounds = parameter_bounds(options)
    if not any(ev.impulse for ev in seq.events):
        bounds[IMPULSE] = (0.0, 0.0)
    parameters = parameters_of(bounds, model_scale(model))
    parameters += [Parameter(fp.name, fp.lower, fp.upper, scale=1.0, guess=fp.guess)
                   for fp in fraction_parameters(seq)]
    return parameters


def share_of(seq: ContactSequence, i: int) -> Callable[[Any], Any]:
    """``p -> s_i``: phase ``i``'s share of the period (:func:`phase_share`, 1): its fraction,
    or of the free fractions ``p[FRACTION_INDEX:]`` (in the order of
    :func:`fraction_parameters`)."""
    n = len(fraction_parameters(seq))
    return lambda p: phase_share(seq, i, [p[_F + k] for k in range(n)])


def phase_duration(seq: ContactSequence, i: int) -> Callable[[Any], Any]:
    """``p -> s_i steps L / v``: phase ``i``'s duration (s), its share of the period (the
    step, or the stride of ``seq.steps = 2`` steps)."""
    share, steps = share_of(seq, i), seq.steps
    return lambda p: share(p) * steps * p[_L] / p[_V]


def period_parameters(seq: ContactSequence, p: Any) -> Any:
    """The parameters ``p`` with the step length ``L`` replaced by the length of the
    period, ``steps L`` (m; ``p`` itself for one step): the costs' denominator and resting
    time are the period's (a stride's cost is per metre of the stride)."""
    if seq.steps == 1:
        return p
    return ca.vertcat(seq.steps * p[_L], p[_V], p[_P])
