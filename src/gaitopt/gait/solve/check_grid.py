"""The check grid of a solve and the first-order error estimate from two grids.

A cost ``J(N)`` computed on ``N`` knots (single support) converges to its limit
``J(inf)`` as the grid is refined. Solved once more on a finer *check grid* of ``M > N``
knots, the change ``J(N) - J(M)`` gives the error of either grid if the error falls as
``C / N`` (first order):

    J(N) - J(inf) = M / (M - N) * (J(N) - J(M))        (3 for 16 -> 24 knots)
    J(M) - J(inf) = N / (M - N) * (J(N) - J(M))        (2 for 24 -> 36 knots)

(:func:`first_order_factor`). On cosine-spaced knots the walking problem converges at
about order 1.3 to 2 (docs/walking.md, section 6), so these factors overestimate the error;
on uniform knots fast walks converge at first order from below. The check grid of a grid
(:func:`check_knots`) has 1.5 times its knots in every phase. ``gaitopt solve`` (the default,
16 + 6 cosine-spaced knots) solves the check grid 24 + 8 after its target grid for the cost
error estimate of the gait file (:mod:`gaitopt.gait.solve.accuracy`), and ``gaitopt study`` solves
its check and refinement sweeps on the same grids (:mod:`gaitopt.study.grid_error`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

#: The check grid of the known grids; any other grid is refined by half its knots.
CHECK_KNOTS: dict[tuple[int, int], tuple[int, int]] = {(16, 6): (24, 8), (8, 5): (16, 6)}


def check_knots(knots: Sequence[int]) -> tuple[int, ...]:
    """The check grid of ``knots`` (single support, double support; or one count per phase):
    :data:`CHECK_KNOTS`, else ``ceil(1.5 * knots)`` in each phase (``(40, 10)`` -> ``(60,
    15)``)."""
    k = tuple(int(v) for v in knots)
    found = CHECK_KNOTS.get((k[0], k[1])) if len(k) == 2 else None
    return found if found is not None else tuple(math.ceil(1.5 * v) for v in k)


def first_order_factor(coarse: int, fine: int, *, of_finer: bool) -> float:
    """The error of a grid from the change between two grids of ``coarse`` and ``fine``
    knots (single support), if the error falls as ``C / knots``: the coarse grid's error is
    the change times ``fine / (fine - coarse)`` (3 for 16 to 24 knots), the fine grid's times
    ``coarse / (fine - coarse)`` (2 for 24 to 36); 1 when ``fine <= coarse``."""
    if fine <= coarse:
        return 1.0
    return (coarse if of_finer else fine) / (fine - coarse)
