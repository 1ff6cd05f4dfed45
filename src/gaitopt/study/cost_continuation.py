"""The cost study's continuation between cases: each case started from the case solved before it.

On a model whose cold staged solves of the costs of transport are slow and stop at IPOPT's
iteration limit (the seven-link model with feet: 10-15 minutes each, docs/costs.md), the
cases of the study (:mod:`gaitopt.study.cost_study`, strategy ``continuation``) are solved in
the order of :meth:`~gaitopt.study.cost_study.CostStudySpec.solve_order` (the metabolic cases
by ascending resting power ``P_rest``, then the work case), and each case starts from its
*neighbour* (:func:`case_neighbour`), a case solved before it:

* its sweep's fixed-speed walk (at the model's start speed) from the neighbour's fixed-speed
  walk at the same speed (:func:`fixed_seeds`). For two metabolic cases this is the same
  problem: at a fixed speed ``v`` the step time is ``T = L / v``, so the resting term
  ``P_rest m T / (W L) = P_rest m / (W v)`` is a constant and the optimum does not depend on
  ``P_rest``; the start is its optimum, with its multipliers (the file's NLP point);
* its speed-free optimum a second time, from the neighbour's speed-free optimum (a
  continuation in the resting power, :func:`neighbour_spec`), in ``<case>/from-<tag>``;
  the lower of the two speed-free optima is the case's (every converged one is a
  candidate, :func:`free_candidates`).

The first case (no neighbour) starts cold, as in the ``cold`` strategy. A case whose
fixed-speed walk failed is solved once more, after all cases, from the nearest case whose
fixed-speed walk converged (:func:`resolve_neighbour`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, SummaryError, SummaryRow, read_summary, rows_of

if TYPE_CHECKING:
    from gaitopt.study.cost_study import CostCase

#: The folder of a case's speed-free optimum started from its neighbour, inside the case's.
NEIGHBOUR_DIR = "from-{tag}"


def case_neighbour(case: CostCase, done: Sequence[CostCase]) -> CostCase | None:
    """The case among ``done`` (solved before) that ``case`` starts from: for a metabolic
    case the metabolic case of nearest resting power (the lower on a tie); for the work case
    the metabolic case of least resting power; None for the paper case or when none is
    done."""
    metabolic = [c for c in done if c.cost == "metabolic" and c.resting_power is not None]
    if case.cost == "paper" or not metabolic:
        return None
    if case.cost == "work":
        return min(metabolic, key=lambda c: c.resting_power or 0.0)
    p = case.resting_power or 0.0
    return min(metabolic, key=lambda c: (abs((c.resting_power or 0.0) - p),
                                         c.resting_power or 0.0))


def _rows(folder: Path) -> list[SummaryRow]:
    try:
        return read_summary(folder / SUMMARY_FILE)
    except SummaryError:
        return []


def fixed_converged(folder: Path, spec: SweepSpec) -> Path | None:
    """The gait file of the fixed-speed walk of the sweep ``spec`` in ``folder`` when it
    converged (its summary row and a file that loads), else None."""
    point = next(p for p in spec.points if p.speed is not None)
    rows = rows_of(_rows(folder), point.variant, speed_mode="fixed")
    if not rows or not rows[0].success:
        return None
    return _converged(folder / rows[0].file)


def _converged(path: Path) -> Path | None:
    try:
        gait = Gait.load(path)
    except (GaitFileError, OSError):
        return None
    return path if gait.success and math.isfinite(gait.cost_value) else None


def fixed_seeds(spec: SweepSpec, neighbour_folder: Path,
                neighbour_spec: SweepSpec) -> dict[str, Path]:
    """The seed of the fixed-speed walk of the sweep ``spec``: the neighbour's fixed-speed
    gait (``neighbour_folder``, its sweep ``neighbour_spec``) when it converged at the same
    speed; else none (a cold start)."""
    mine = next(p for p in spec.points if p.speed is not None)
    theirs = next(p for p in neighbour_spec.points if p.speed is not None)
    if theirs.speed is None or mine.speed is None or abs(theirs.speed - mine.speed) > 1e-12:
        return {}
    found = fixed_converged(neighbour_folder, neighbour_spec)
    return {} if found is None else {mine.key: found}


def neighbour_folder(case_folder: Path, neighbour: CostCase) -> Path:
    """``<case>/from-<neighbour's tag>``."""
    return case_folder / NEIGHBOUR_DIR.format(tag=neighbour.tag)


def neighbour_spec(spec: SweepSpec, speed: float) -> SweepSpec:
    """The sweep that solves the speed-free optimum of ``spec`` again from a neighbour's
    speed-free optimum at ``speed`` (m/s): the walk at that speed and the speed-free walk,
    each started from the neighbour's gait (no continuation between them)."""
    return replace(spec, speeds=(speed,), continuation=False)


def free_candidates(case_folder: Path, variant: str) -> list[tuple[float, str, SummaryRow]]:
    """Every converged speed-free optimum of one case: ``(cost, where, row)`` with ``where``
    the sweep folder relative to the case's (``""`` for the case's own sweep,
    ``from-<tag>`` for a start from a neighbour), lowest cost first."""
    found = []
    folders = [case_folder, *sorted(p for p in case_folder.glob(NEIGHBOUR_DIR.format(tag="*"))
                                    if p.is_dir())]
    for folder in folders:
        free = rows_of(_rows(folder), variant, speed_mode="free")
        if free and free[0].success and math.isfinite(free[0].cost) and free[0].file:
            where = "" if folder == case_folder else folder.name
            found.append((free[0].cost, where, free[0]))
    return sorted(found, key=lambda c: c[0])


def best_free(case_folder: Path, variant: str) -> tuple[Path, SummaryRow] | None:
    """The lowest converged speed-free optimum of one case (its gait file and summary row),
    or None."""
    for _, where, row in free_candidates(case_folder, variant):
        path = _converged((case_folder / where if where else case_folder) / row.file)
        if path is not None:
            return path, row
    return None


def resolve_neighbour(case: CostCase, order: Sequence[CostCase],
                      has_fixed: Sequence[CostCase]) -> CostCase | None:
    """For a case whose fixed-speed walk failed: the case of ``has_fixed`` (those whose
    fixed-speed walk converged) to start it from: its neighbour among them
    (:func:`case_neighbour`), else the nearest in ``order``; None when there is none."""
    others = [c for c in has_fixed if c != case]
    found = case_neighbour(case, others)
    if found is not None or not others:
        return found
    index = {c: i for i, c in enumerate(order)}
    here = index.get(case, 0)
    return min(others, key=lambda c: (abs(index.get(c, 0) - here), index.get(c, 0)))


__all__ = ["NEIGHBOUR_DIR", "best_free", "case_neighbour", "fixed_converged", "fixed_seeds",
           "free_candidates", "neighbour_folder", "neighbour_spec", "resolve_neighbour"]
