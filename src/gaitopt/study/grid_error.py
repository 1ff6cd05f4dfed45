"""The grid error of a study: its sweep compared with a check sweep on a finer grid.

``gaitopt study`` solves the sweep on its grid (by default 16 + 6 knots, torques free to jump)
and then a *check sweep* of the same problem on a finer grid (:func:`check_knots`, 24 + 8 for
the default) at the same speeds and each variant's speed-free optimum, in
``<study>/check-grid``. (All speeds: the sweep continues from speed to speed, and steps of
3 m/min take about 13 IPOPT iterations where steps of 12 m/min took about 200, so a sparse
check would cost more.) For every point solved on both grids the difference of
the study's value from the check grid's is the estimate of the study's discretization error
(the last two refinements):

* cost: ``|J(grid) - J(check)| / J(check)`` (relative);
* step length ``L(check) - L(grid)`` (m) and, for the speed-free optimum, the speed
  ``v(check) - v(grid)`` (m/min): how far they move from the study's grid to the finer one.

It is an estimate, not a bound: with the default control model the cost converges fast
(docs/walking.md, section 6), so the difference mostly reflects the coarser grid's error.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from gaitopt.study.plan import SETTINGS_FILE
from gaitopt.study.summary import SUMMARY_FILE, SummaryRow, read_summary

#: The check grid of the known study grids; any other grid is refined by half its knots.
CHECK_KNOTS: dict[tuple[int, int], tuple[int, int]] = {(16, 6): (24, 8), (8, 5): (16, 6)}
#: The relative cost change the statements single out: where the estimate exceeds it, they say
#: at how many points and at which speeds.
WITHIN = 0.01
#: The folder of the check sweep inside the study directory.
CHECK_DIR = "check-grid"


def check_knots(knots: tuple[int, int]) -> tuple[int, int]:
    """The finer grid of the check sweep: :data:`CHECK_KNOTS`, else 1.5 times the knots."""
    k = (int(knots[0]), int(knots[1]))
    return CHECK_KNOTS.get(k, (math.ceil(1.5 * k[0]), math.ceil(1.5 * k[1])))


@dataclass(frozen=True)
class PointError:
    """One point solved on both grids: the study's row and the check grid's."""

    row: SummaryRow
    check: SummaryRow

    @property
    def cost(self) -> float:
        """``|J(grid) - J(check)| / J(check)``."""
        return abs(self.row.cost - self.check.cost) / abs(self.check.cost)

    @property
    def step_length(self) -> float:
        """``L(check) - L(grid)`` (m): how the step length moves on the finer grid."""
        return self.check.step_length - self.row.step_length

    @property
    def speed_m_min(self) -> float:
        """``v(check) - v(grid)`` (m/min; 0 at a fixed speed)."""
        return self.check.speed_m_min - self.row.speed_m_min


def _key(row: SummaryRow) -> tuple[str, str, float]:
    speed = math.nan if row.speed_mode == "free" else round(row.speed_m_min, 2)
    return (row.variant, row.speed_mode, speed)


@dataclass(frozen=True)
class GridError:
    """The study's grid and the check grid, and every point solved on both."""

    knots: tuple[int, int]
    control_model: str
    check_knots: tuple[int, int] | None
    points: tuple[PointError, ...]

    @staticmethod
    def compare(rows: Sequence[SummaryRow], check_rows: Sequence[SummaryRow], *,
                knots: tuple[int, int], control_model: str,
                check: tuple[int, int] | None) -> GridError:
        """Pair the converged rows of the study and of the check sweep by variant, speed mode
        and speed (0.01 m/min)."""
        ok = {_key(r): r for r in check_rows if r.success and math.isfinite(r.cost)}
        pairs = []
        for r in rows:
            if not (r.success and math.isfinite(r.cost)):
                continue
            key = _key(r)
            found = (ok.get(key) if r.speed_mode == "fixed" else
                     next((c for k, c in ok.items() if k[:2] == key[:2]), None))
            if found is not None:
                pairs.append(PointError(r, found))
        return GridError(knots, control_model, check, tuple(pairs))

    @property
    def grid(self) -> str:
        """``16+6 knots, control model jumps``."""
        return f"{self.knots[0]}+{self.knots[1]} knots, control model {self.control_model}"

    def of(self, rows: Sequence[SummaryRow | None]) -> list[PointError]:
        """The checked points among ``rows`` (by identity of variant, mode and speed)."""
        keys = {_key(r) for r in rows if r is not None}
        return [p for p in self.points if _key(p.row) in keys]

    def free(self, variant: str) -> PointError | None:
        """The speed-free optimum of ``variant`` on both grids, or None."""
        return next((p for p in self.points if p.row.variant == variant
                     and p.row.speed_mode == "free"), None)

    def statement(self, points: Sequence[PointError] | None = None, *,
                  what: str = "cost") -> str:
        """One sentence: the grid and the largest estimate over ``points`` (default: all)
        of ``what`` (``cost`` relative, or ``step length`` in m)."""
        chosen = list(self.points if points is None else points)
        if self.check_knots is None or not chosen:
            return f"Grid: {self.grid}; no error estimate (no point solved on a finer grid)."
        fixed = sum(p.row.speed_mode == "fixed" for p in chosen)
        free = len(chosen) - fixed
        where = ", ".join(part for part in (
            f"{fixed} fixed-speed point{'s' if fixed != 1 else ''}" if fixed else "",
            f"{free} speed-free optim{'a' if free != 1 else 'um'}" if free else "") if part)
        check = f"{self.check_knots[0]}+{self.check_knots[1]} knots"
        if what == "step length":
            worst = max(abs(p.step_length) for p in chosen)
            value = f"step length within {worst:.4f} m"
        else:
            worst = max(p.cost for p in chosen)
            value = f"cost within {100 * worst:.2f} %"
            above = [p for p in chosen if p.cost > WITHIN]
            if above:
                speeds = sorted(p.row.speed_m_min for p in above)
                span = (f"{speeds[0]:g} m/min" if speeds[0] == speeds[-1] else
                        f"{speeds[0]:g}-{speeds[-1]:g} m/min")
                below = max((p.cost for p in chosen if p.cost <= WITHIN), default=0.0)
                value += (f"; above {100 * WITHIN:g} % at {len(above)} of {len(chosen)} "
                          f"points ({span}), within {100 * below:.2f} % at the others")
        return (f"Grid: {self.grid}. Error estimate (change to {check} at {where}): "
                f"{value}.")


def sweep_grid(sweep_dir: str | os.PathLike[str]) -> tuple[tuple[int, int], str] | None:
    """The knots and control model of a sweep, from its ``sweep.json`` (None if unreadable;
    a sweep written before control models existed used the paper's)."""
    path = Path(sweep_dir) / SETTINGS_FILE
    try:
        options = json.loads(path.read_text(encoding="utf-8"))["settings"]["options"]
        knots = options["knots"]
        return (int(knots[0]), int(knots[1])), str(options.get("control_model", "paper"))
    except (OSError, ValueError, KeyError, TypeError, IndexError):
        return None


def grid_error(sweep_dir: str | os.PathLike[str], rows: Sequence[SummaryRow],
               check_dir: str | os.PathLike[str] | None = None) -> GridError | None:
    """The grid error of the sweep in ``sweep_dir`` (its ``rows``) against the check sweep in
    ``check_dir`` (default ``<sweep_dir>/check-grid``); without a check sweep, the grid
    alone (no points). None when the sweep's grid is unknown (no ``sweep.json``)."""
    grid = sweep_grid(sweep_dir)
    if grid is None:
        return None
    check = Path(check_dir) if check_dir is not None else Path(sweep_dir) / CHECK_DIR
    check_grid = sweep_grid(check)
    summary = check / SUMMARY_FILE
    if check_grid is None or not summary.exists() or check_grid[1] != grid[1]:
        return GridError(grid[0], grid[1], None, ())
    return GridError.compare(rows, read_summary(summary), knots=grid[0], control_model=grid[1],
                             check=check_grid[0])
