"""The convergence passes of ``gaitopt study`` after each sweep (docs/studies.md).

A sweep's speed-free optimum of a variant is warm-started from one point of its chain (the
chain's cold start, :attr:`gaitopt.study.plan.SweepSpec.start`), and the problem has several
local optima (docs/feet.md: two 5 % apart for ``seven-link``). A speed-free optimum that costs
more than a fixed-speed point of the same variant on the same grid is no optimum of the sweep:
the speed-free walk at that point's speed and step would be cheaper. :func:`free_restarts`
names those variants (and those whose speed-free solve failed) with the fixed-speed point of
lowest cost; the study then solves the speed-free walk again from that point's gait
(:func:`restart_spec`, in ``<sweep>/free-restart/<variant>``) and keeps the lower of the two
optima (:func:`lower_gait`), so each reported optimum is the lowest found.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import SummaryRow, rows_of

#: The folder of the restarts of the speed-free optima, inside the sweep's.
RESTART_DIR = "free-restart"
#: A speed-free optimum above the lowest fixed-speed point by more than this (relative) is
#: solved again; below it the two are one optimum up to the solver's tolerance.
RESTART_MARGIN = 1e-6


def free_restarts(rows: Sequence[SummaryRow], variants: Sequence[str]
                  ) -> dict[str, SummaryRow]:
    """Variant -> its converged fixed-speed row of lowest cost, for each variant whose
    speed-free optimum failed, is missing, or costs more than that row (by more than
    :data:`RESTART_MARGIN`, relative)."""
    out = {}
    for variant in variants:
        fixed = [r for r in rows_of(rows, variant, speed_mode="fixed")
                 if math.isfinite(r.cost) and r.file]
        if not fixed:
            continue
        best = min(fixed, key=lambda r: r.cost)
        free = [r for r in rows_of(rows, variant, speed_mode="free")
                if math.isfinite(r.cost)]
        if not free or free[0].cost > best.cost * (1.0 + RESTART_MARGIN):
            out[variant] = best
    return out


def restart_spec(spec: SweepSpec, variant: str, row: SummaryRow) -> SweepSpec:
    """The sweep that solves ``variant``'s speed-free walk again from ``row`` (a fixed-speed
    point of ``spec``): that point and the speed-free walk, both seeded with ``row``'s gait
    (no continuation)."""
    return replace(spec, speeds=(row.speed_m_s,), variants=(variant,), free_speed=True,
                   continuation=False)


def restart_seeds(spec: SweepSpec, gait_file: Path) -> dict[str, Path]:
    """Every point of a :func:`restart_spec` seeded with ``gait_file``."""
    return {p.key: gait_file for p in spec.points}


def lower_gait(first: Path, second: Path) -> Path | None:
    """Whichever of two gait files of one point holds a converged gait of lower cost (``first``
    on a tie or when ``second`` is missing or failed); None when neither does."""
    found: list[tuple[float, int, Path]] = []
    for rank, path in enumerate((first, second)):
        try:
            gait = Gait.load(path)
        except (GaitFileError, OSError):
            continue
        if gait.success and math.isfinite(gait.cost_value):
            found.append((gait.cost_value, rank, path))
    return min(found)[2] if found else None


def restart_folder(directory: Path, variant: str) -> Path:
    """``<sweep>/free-restart/<variant>``."""
    return directory / RESTART_DIR / variant


__all__ = ["RESTART_DIR", "RESTART_MARGIN", "free_restarts", "lower_gait", "restart_folder",
           "restart_seeds", "restart_spec"]
