"""Mesh refinement: split intervals whose error estimate exceeds a tolerance, warm-start, repeat.

Round r solves on the current mesh; every interval k with error ``e_k > tol`` is split into
``clip(ceil((e_k / tol)^(1 / (order + 1))), 2, max_split)`` equal parts (the local error of a
method of order p scales like h^(p+1)); the next round is warm-started from the previous
result interpolated onto the new mesh. Stops when ``max_error <= tol``, when a solve fails, or
after ``max_rounds`` rounds or ``max_intervals`` intervals in a phase.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gaitopt.ocp.guess import Guess
from gaitopt.ocp.mesh import IntervalsSpec, split_intervals
from gaitopt.ocp.problem import Problem
from gaitopt.ocp.result import METHODS, Result
from gaitopt.ocp.transcription import Transcription, transcribe


@dataclass(frozen=True)
class Refinement:
    """Outcome of :func:`refine`: the final result, every round's result, whether tol holds."""

    result: Result
    history: tuple[Result, ...]
    converged: bool

    @property
    def intervals(self) -> tuple[tuple[int, ...], ...]:
        """Intervals per phase in each round."""
        return tuple(tuple(m.size - 1 for m in r.mesh) for r in self.history)


def refined_mesh(result: Result, tol: float, *, max_split: int = 4) -> tuple[np.ndarray, ...]:
    """The next mesh: each interval of each phase with error > tol split (module docstring)."""
    order = METHODS[result.method].order
    out = []
    for ph, tau in zip(result.phases, result.mesh, strict=True):
        err = np.nan_to_num(ph.error, nan=np.inf)
        ratio = np.maximum(err / tol, 1.0)
        pieces = np.where(err > tol,
                          np.clip(np.ceil(ratio ** (1.0 / (order + 1))), 2, max_split), 1)
        out.append(split_intervals(tau, pieces.astype(np.int64)))
    return tuple(out)


def refine(problem: Problem, *, tol: float, method: str = "hermite-simpson",
           intervals: IntervalsSpec | Mapping[str, IntervalsSpec] | None = None,
           guess: Guess | Result | None = None, max_rounds: int = 8,
           max_intervals: int = 2000, solve_options: Mapping[str, Any] | None = None,
           **transcribe_options: Any) -> Refinement:
    """Solve ``problem`` and refine its mesh until every interval error is <= ``tol``."""
    if not (tol > 0 and math.isfinite(tol)):
        raise ValueError(f"tol must be finite and > 0, got {tol}")
    tr: Transcription = transcribe(problem, method=method, intervals=intervals,
                                   **transcribe_options)
    history: list[Result] = []
    current: Guess | Result | None = guess
    for _ in range(max_rounds):
        res = tr.solve(current, options=solve_options)
        history.append(res)
        if not res.success or res.max_error <= tol:
            break
        mesh = refined_mesh(res, tol)
        if max(m.size - 1 for m in mesh) > max_intervals:
            break
        tr = transcribe(problem, method=method,
                        intervals={ph.name: m for ph, m in zip(problem.phases, mesh,
                                                               strict=True)},
                        **transcribe_options)
        current = res
    final = history[-1]
    return Refinement(final, tuple(history), final.success and final.max_error <= tol)
