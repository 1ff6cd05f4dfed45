"""Meshes: the knot positions of each phase in normalised time tau in [0, 1].

A phase of duration T starting at t0 has knots ``t_k = t0 + T * tau_k``, k = 0..K-1, with
``tau_0 = 0 < tau_1 < ... < tau_{K-1} = 1``; interval k is ``[t_k, t_{k+1}]`` of length
``h_k = T * (tau_{k+1} - tau_k)``; N = K - 1 intervals.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.problem import Problem
from gaitopt.ocp.validate import ProblemError

Mesh = tuple[NDArray[np.float64], ...]
"""One normalised knot array (K_i,) per phase, in phase order."""

IntervalsSpec = int | Sequence[float] | NDArray[np.float64]


def uniform(intervals: int) -> NDArray[np.float64]:
    """``intervals + 1`` equally spaced knots on [0, 1]."""
    if int(intervals) != intervals or intervals < 1:
        raise ProblemError(f"intervals must be an integer >= 1, got {intervals!r}")
    return np.linspace(0.0, 1.0, int(intervals) + 1)


def check_points(tau: Sequence[float] | NDArray[np.float64], where: str) -> NDArray[np.float64]:
    """A validated knot array: starts at 0, ends at 1, strictly increasing."""
    arr = np.asarray(tau, dtype=float)
    if arr.ndim != 1 or arr.size < 2:
        raise ProblemError(f"{where}: mesh points must be a 1-D array of >= 2 values")
    if not (math.isclose(arr[0], 0.0, abs_tol=1e-14) and math.isclose(arr[-1], 1.0,
                                                                       abs_tol=1e-14)):
        raise ProblemError(f"{where}: mesh points must start at 0 and end at 1")
    if np.any(np.diff(arr) <= 0):
        raise ProblemError(f"{where}: mesh points must be strictly increasing")
    out = arr.copy()
    out[0], out[-1] = 0.0, 1.0
    return out


def make_mesh(problem: Problem,
              intervals: IntervalsSpec | Mapping[str, IntervalsSpec] | None = None) -> Mesh:
    """The mesh for every phase.

    ``intervals``: None (each phase's own ``Phase.intervals``), an int for all phases, or a
    mapping from phase name to an int (uniform) or an array of normalised knots.
    """
    names = [ph.name for ph in problem.phases]
    if isinstance(intervals, Mapping):
        for key in intervals:
            if key not in names:
                raise ProblemError(f"intervals: {key!r} is not a phase (phases: {names})")
    out = []
    for ph in problem.phases:
        spec: IntervalsSpec | None
        if intervals is None:
            spec = ph.intervals
        elif isinstance(intervals, Mapping):
            spec = intervals.get(ph.name, ph.intervals)
        else:
            spec = intervals
        if isinstance(spec, int | np.integer):
            out.append(uniform(int(spec)))
        else:
            out.append(check_points(spec, f"phase {ph.name!r} mesh"))
    return tuple(out)


def split_intervals(tau: NDArray[np.float64], pieces: NDArray[np.int64]) -> NDArray[np.float64]:
    """Split interval k of ``tau`` into ``pieces[k] >= 1`` equal parts; returns new knots."""
    if pieces.shape != (tau.size - 1,):
        raise ValueError(f"pieces must have shape ({tau.size - 1},), got {pieces.shape}")
    new = [tau[:1]]
    for k in range(tau.size - 1):
        new.append(np.linspace(tau[k], tau[k + 1], int(pieces[k]) + 1)[1:])
    return np.concatenate(new)
