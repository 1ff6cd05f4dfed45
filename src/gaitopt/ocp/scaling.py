"""Scaling of decision variables and constraints.

The NLP is posed in scaled variables ``w_hat = w / d_w`` and scaled constraints
``g_hat = g / d_g`` with positive diagonal scales, and the objective ``J / objective_scale``.
Scales come from the user where given (``Phase.state_scales``, ``Parameter.scale``, ...), else
from the bounds: the largest finite bound magnitude, or 1 when no bound is finite or both are
0. Defects and state linkages take the scale of their state, so a scaled defect of 1 means an
error of one state unit. With ``enabled=False`` every scale is 1.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.functions import scale_from_bounds
from gaitopt.ocp.layout import Layout
from gaitopt.ocp.problem import Phase, Problem
from gaitopt.ocp.validate import as_bound

Array = NDArray[np.float64]


def _named_scales(names: tuple[str, ...] | list[str], given: dict[str, float] | object,
                  bounds: object, where: str) -> Array:
    out = np.ones(len(names))
    for j, name in enumerate(names):
        if name in given:  # type: ignore[operator]
            out[j] = float(given[name])  # type: ignore[index]
        elif name in bounds:  # type: ignore[operator]
            lo, hi = as_bound(bounds[name], f"{where} {name!r}")  # type: ignore[index]
            out[j] = float(scale_from_bounds(np.array([lo]), np.array([hi]))[0])
    return out


def state_scales(phase: Phase, enabled: bool = True) -> Array:
    """Scale of each state of ``phase``, (n,)."""
    if not enabled:
        return np.ones(phase.n_states)
    return _named_scales(list(phase.states), phase.state_scales, phase.state_bounds,
                         f"phase {phase.name!r} state_bounds")


def control_scales(phase: Phase, enabled: bool = True) -> Array:
    """Scale of each control of ``phase``, (m,)."""
    if not enabled:
        return np.ones(phase.n_controls)
    return _named_scales(list(phase.controls), phase.control_scales, phase.control_bounds,
                         f"phase {phase.name!r} control_bounds")


def variable_scales(problem: Problem, layout: Layout, enabled: bool = True) -> Array:
    """Scale of every entry of w, (layout.size,)."""
    d = np.ones(layout.size)
    if not enabled:
        return d
    for ph, pl in zip(problem.phases, layout.phases, strict=True):
        d[pl.state_indices()] = state_scales(ph)[None, :]
        d[pl.midpoint_indices()] = state_scales(ph)[None, :]
        if ph.n_controls:
            d[pl.control_indices()] = control_scales(ph)[None, :]
        if pl.duration_index is not None:
            spec = ph.duration_spec()
            d[pl.duration_index] = (spec.scale if spec.scale is not None else
                                    scale_from_bounds(np.array([spec.lower]),
                                                      np.array([spec.upper]))[0])
    for par in problem.parameters:
        i = layout.parameter(par.name)
        if par.scale is not None:
            d[i] = par.scale
        else:
            d[i] = scale_from_bounds(np.array([par.lower]), np.array([par.upper]))[0]
    assert np.all(d > 0) and all(math.isfinite(v) for v in d)
    return d
