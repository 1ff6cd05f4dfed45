"""The costates a gait record carries: :func:`gaitopt.ocp.costates` of the final solve.

The walking solution keeps its final :class:`~gaitopt.ocp.Result` but not its transcription;
the transcription of the same problem on the result's grid is the process-wide cached one
(:func:`gaitopt.gait.solve.transcriptions.transcription_for`: the solve's own when recorded in the
solving process, otherwise rebuilt from the disk cache of the problem's functions).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from gaitopt.gait.solve.staged_run import StagedRun
from gaitopt.gait.solve.transcriptions import Grid, transcription_for
from gaitopt.ocp import ProblemError, costates

Array = NDArray[np.float64]


def solution_costates(solution: StagedRun) -> Mapping[str, Array]:
    """``{phase: (K, n)}`` costates at the knots by the phase's state order, for the phases
    whose costates the transcription gives (not those with knot states, e.g. a placed floating
    base); empty for a failed solve or when the result does not fit the options' problem
    (another cost, say), or when CasADi cannot evaluate them: a record never fails for its
    costates."""
    res = solution.result
    if not res.success:
        return {}
    sizes = [m.size for m in res.mesh]
    knots = solution.options.knots
    # A single-support step has one phase: its knots may be given alone (by phase name).
    counts: Grid = (tuple(sizes[:2]) if len(sizes) > 1 else
                    (sizes[0], knots[1]) if len(knots) > 1 else (sizes[0],))
    for grid in (counts, tuple(res.mesh)):
        try:
            tr = transcription_for(solution.model, solution.options, grid)
        except (ProblemError, ValueError):
            continue
        same_mesh = len(tr.mesh) == len(res.mesh) and all(
            a.shape == b.shape and np.allclose(a, b) for a, b in zip(tr.mesh, res.mesh,
                                                                    strict=True))
        if same_mesh:
            try:
                return costates(tr, res)
            except (ProblemError, RuntimeError):  # CasADi's errors are RuntimeErrors: the
                return {}                          # record is written without costates
    return {}
