"""The grid error of a study: its sweep compared with a check sweep on a finer grid.

``gaitopt study`` solves the sweep on its grid (by default 16 + 6 knots, torques free to jump)
and then a *check sweep* of the same problem on a finer grid (:func:`check_knots`, 24 + 8 for
the default) at the same speeds and each variant's speed-free optimum, in
``<study>/check-grid``. (All speeds: the sweep continues from speed to speed, and steps of
3 m/min take about 13 IPOPT iterations where steps of 12 m/min took about 200, so a sparse
check would cost more.) For every point solved on both grids the change between them is

* cost: ``|J(grid) - J(check)| / J(check)`` (relative);
* step length ``L(check) - L(grid)`` (m) and, for the speed-free optimum, the speed
  ``v(check) - v(grid)`` (m/min): how far they move from the study's grid to the finer one;

and the estimate of the study's discretization error is that change times the first-order
factor (:func:`first_order_factor`: 3 from 16 to 24 knots): the error if it fell as
``1 / knots``. On uniform knots fast walks converge at about that order, so the change alone
understated their error about three times; on the cosine-spaced knots of the study the
measured order is 1.3 to 2 and the estimate is an overestimate (docs/walking.md, section 6).
It is an estimate, not a bound.

**Refinement.** Where that estimate exceeds :data:`WITHIN` (1 %) for the cost, the step length
(relative) or (speed-free optimum, relative) the speed, ``gaitopt study`` re-solves the point
on a third, finer grid (:func:`check_knots` of the check grid: 36 + 12 for the default) in a
*refinement sweep*, ``<study>/refine-grid``, each chain warm-started from the check sweep's
gait at the same point. A point solved there is reported with its refined value, and its error
estimate comes from the change between its last two grids, from the check grid to the
refinement grid (``|J(refine) - J(check)| / J(refine)``; step length and speed
``refine - check``; times 2, the first-order factor of the finer grid):
:meth:`GridError.reported` gives the rows the report shows.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from gaitopt.gait.solve.check_grid import CHECK_KNOTS, check_knots, first_order_factor
from gaitopt.study.plan import SETTINGS_FILE
from gaitopt.study.summary import SUMMARY_FILE, SummaryRow, read_summary

#: The relative cost change the statements single out: where the estimate exceeds it, they say
#: at how many points and at which speeds.
WITHIN = 0.01
#: The folder of the check sweep inside the study directory.
CHECK_DIR = "check-grid"
#: The folder of the (first) refinement sweep inside the study directory; the later levels
#: are ``refine-grid-2``, ``refine-grid-3`` (:func:`refine_dir_name`).
REFINE_DIR = "refine-grid"
#: The most refinement levels a study solves (36 + 12, 54 + 18 and 81 + 27 knots after the
#: default's 16 + 6 and 24 + 8).
MAX_REFINE_LEVELS = 3


def refine_dir_name(level: int) -> str:
    """The folder of refinement level ``level`` (1, 2, ...) inside the study directory."""
    return REFINE_DIR if level == 1 else f"{REFINE_DIR}-{level}"


@dataclass(frozen=True)
class PointError:
    """One point solved on two grids: ``row`` the value the study reports, ``check`` the same
    point on the other grid of its estimate (finer, or with ``refined`` the coarser check
    grid, ``row`` then coming from the refinement sweep)."""

    row: SummaryRow
    check: SummaryRow
    refined: bool = False
    #: The first-order factor from the change between the two grids to the error of the
    #: reported one (:func:`first_order_factor`).
    factor: float = 1.0
    #: The refinement level ``row`` comes from (0: the study's grid, 1: ``refine-grid``, ...)
    #: and the knots of ``row``'s and ``check``'s grids (None when not known).
    level: int = 0
    grid: tuple[int, int] | None = None
    check_grid: tuple[int, int] | None = None

    @property
    def _finer(self) -> SummaryRow:
        return self.row if self.refined else self.check

    @property
    def _coarser(self) -> SummaryRow:
        return self.check if self.refined else self.row

    @property
    def cost(self) -> float:
        """``|J(grid) - J(finer grid)| / J(finer grid)`` of the point's two grids."""
        return abs(self.row.cost - self.check.cost) / abs(self._finer.cost)

    @property
    def step_length(self) -> float:
        """``L(finer) - L(coarser)`` (m): how the step length moves on the finer grid."""
        return self._finer.step_length - self._coarser.step_length

    @property
    def speed_m_min(self) -> float:
        """``v(finer) - v(coarser)`` (m/min; 0 at a fixed speed)."""
        return self._finer.speed_m_min - self._coarser.speed_m_min

    @property
    def cost_error(self) -> float:
        """The estimate of the reported cost's relative error: ``factor * cost``."""
        return self.factor * self.cost

    @property
    def step_error(self) -> float:
        """The estimate of the reported step length's error (m): ``factor * |step_length|``."""
        return self.factor * abs(self.step_length)

    @property
    def speed_error(self) -> float:
        """The estimate of the reported speed's error (m/min; 0 at a fixed speed)."""
        return self.factor * abs(self.speed_m_min)

    @property
    def step_relative(self) -> float:
        """The step length's error estimate relative to the finer grid's step length."""
        return self.step_error / abs(self._finer.step_length)

    @property
    def relative(self) -> float:
        """The largest estimated relative error of the cost, the step length and (speed-free
        optimum) the speed: what decides a refinement."""
        return max(self.cost_error, self.step_error / abs(self._finer.step_length),
                   self.speed_error / abs(self._finer.speed_m_min))


def _key(row: SummaryRow) -> tuple[str, str, float]:
    speed = math.nan if row.speed_mode == "free" else round(row.speed_m_min, 2)
    return (row.variant, row.speed_mode, speed)


@dataclass(frozen=True)
class RefineLevel:
    """One refinement sweep of a study: its converged rows, its knots, and its folder
    relative to the study's (``refine-grid``, ``refine-grid-2``, ...)."""

    rows: tuple[SummaryRow, ...]
    knots: tuple[int, int]
    prefix: str = REFINE_DIR


@dataclass(frozen=True)
class GridError:
    """The study's grid, the check grid, the refinement grids (``levels``: the knots of each
    refinement sweep that re-solved a point; ``refine_knots`` the first, None without one),
    and every point solved on two of them (refined points with their last two)."""

    knots: tuple[int, int]
    control_model: str
    check_knots: tuple[int, int] | None
    points: tuple[PointError, ...]
    refine_knots: tuple[int, int] | None = None
    spacing: str = "uniform"
    levels: tuple[tuple[int, int], ...] = ()

    @staticmethod
    def compare(rows: Sequence[SummaryRow], check_rows: Sequence[SummaryRow], *,
                knots: tuple[int, int], control_model: str,
                check: tuple[int, int] | None,
                refine_rows: Sequence[SummaryRow] = (),
                refine: tuple[int, int] | None = None,
                refine_prefix: str = REFINE_DIR,
                refine_levels: Sequence[RefineLevel] = ()) -> GridError:
        """Pair the converged rows of the study and of the check sweep by variant, speed mode
        and speed (0.01 m/min); a point also converged in refinement sweeps is paired as
        (its row on the finest of them, its row on the grid before), the row's file made
        relative to the study (the level's ``prefix``). ``refine_levels`` are the
        refinement sweeps from coarse to fine; ``refine_rows``, ``refine`` and
        ``refine_prefix`` give a single one."""
        levels = list(refine_levels)
        if refine is not None and not levels:
            levels = [RefineLevel(tuple(refine_rows), refine, refine_prefix)]
        ok = _converged(check_rows)
        fine = [_converged(level.rows) for level in levels]
        pairs = []
        for r in rows:
            if not (r.success and math.isfinite(r.cost)):
                continue
            found = _find(ok, r)
            if found is None:
                continue
            point = PointError(r, found, factor=first_order_factor(knots[0], check[0],
                                                                   of_finer=False)
                               if check else 1.0, grid=knots, check_grid=check)
            before, before_knots = found, check
            for k, (level, solved) in enumerate(zip(levels, fine, strict=True), start=1):
                better = _find(solved, r)
                if better is None:
                    continue
                factor = (first_order_factor(before_knots[0], level.knots[0], of_finer=True)
                          if before_knots else 1.0)
                point = PointError(replace(better, file=f"{level.prefix}/{better.file}"
                                           if better.file else ""),
                                   before, refined=True, factor=factor, level=k,
                                   grid=level.knots, check_grid=before_knots)
                before, before_knots = better, level.knots
            pairs.append(point)
        used = tuple(level.knots for k, level in enumerate(levels, start=1)
                     if any(p.level >= k for p in pairs))
        return GridError(knots, control_model, check, tuple(pairs),
                         used[0] if used else None, levels=used)

    @property
    def grid(self) -> str:
        """``16+6 knots, control model jumps`` (``16+6 cosine-spaced knots, ...``)."""
        spaced = "" if self.spacing == "uniform" else f" {self.spacing}-spaced"
        return (f"{self.knots[0]}+{self.knots[1]}{spaced} knots, control model "
                f"{self.control_model}")

    def of(self, rows: Sequence[SummaryRow | None]) -> list[PointError]:
        """The checked points among ``rows`` (by identity of variant, mode and speed)."""
        keys = {_key(r) for r in rows if r is not None}
        return [p for p in self.points if _key(p.row) in keys]

    def free(self, variant: str) -> PointError | None:
        """The speed-free optimum of ``variant`` on both grids, or None."""
        return next((p for p in self.points if p.row.variant == variant
                     and p.row.speed_mode == "free"), None)

    def to_refine(self, level: int | None = None) -> list[PointError]:
        """The points whose estimate exceeds :data:`WITHIN` (cost, step length or speed,
        relative): not yet refined (``level`` None), or reported from refinement level
        ``level - 1`` (those refinement level ``level`` re-solves; 1: not yet refined)."""
        at = 0 if level is None else level - 1
        return [p for p in self.points if p.level == at and p.relative > WITHIN]

    def reported(self, rows: Sequence[SummaryRow]) -> list[SummaryRow]:
        """``rows`` (the study's) with each refined point's row in place of its own."""
        better = {_key(p.row): p.row for p in self.points if p.refined}
        return [better.get(_key(r), r) for r in rows]

    def statement(self, points: Sequence[PointError] | None = None, *,
                  what: str = "cost") -> str:
        """One sentence: the grid and the largest estimate over ``points`` (default: all)
        of ``what`` (``cost`` relative, or ``step length`` in m and relative)."""
        chosen = list(self.points if points is None else points)
        if self.check_knots is None or not chosen:
            return f"Grid: {self.grid}; no error estimate (no point solved on a finer grid)."
        fixed = sum(p.row.speed_mode == "fixed" for p in chosen)
        free = len(chosen) - fixed
        where = ", ".join(part for part in (
            f"{fixed} fixed-speed point{'s' if fixed != 1 else ''}" if fixed else "",
            f"{free} speed-free optim{'a' if free != 1 else 'um'}" if free else "") if part)
        check = _knots(self.check_knots)
        if what == "step length":
            worst = max(p.step_error for p in chosen)
            relative = max(p.step_relative for p in chosen)
            value = f"step length within {worst:.4f} m and {100 * relative:.2f} %"
            above = [p for p in chosen if p.step_relative > WITHIN]
            errors = [p.step_relative for p in chosen]
        else:
            worst = max(p.cost_error for p in chosen)
            value = f"cost within {100 * worst:.2f} %"
            above = [p for p in chosen if p.cost_error > WITHIN]
            errors = [p.cost_error for p in chosen]
        if above:
            below = max((e for e in errors if e <= WITHIN), default=0.0)
            value += (f"; above {100 * WITHIN:g} % at {len(above)} of {len(chosen)} "
                      f"points ({_span(above)}), within {100 * below:.2f} % at the others")
        refined = [p for p in chosen if p.refined]
        factor = f"{chosen[0].factor:g} x " if chosen[0].factor != 1.0 else ""
        if not refined or not self.levels:
            return (f"Grid: {self.grid}. Error estimate ({factor}the change to {check} at "
                    f"{where}): {value}.")
        shown = [(k, grid, [p for p in refined if p.level == k])
                 for k, grid in enumerate(self.levels, start=1)]
        shown = [(k, grid, at) for k, grid, at in shown if at]
        grids = ", ".join(
            f"{_knots(grid)} at the {len(at)} point{'s' if len(at) != 1 else ''} "
            f"({_span(at)})" for _, grid, at in shown)
        coarse = next((p.factor for p in chosen if not p.refined), None)
        changes = ", ".join(
            f"{at[0].factor:g} x the change from {_knots(at[0].check_grid or self.check_knots)}"
            f" to {_knots(grid)}" for _, grid, at in shown)
        return (f"Grid: {self.grid}, and {grids} whose estimate exceeded "
                f"{100 * WITHIN:g} % (re-solved). Error estimate (first order from each "
                f"point's last two grids: "
                + (f"{coarse:g} x the change to {check}, " if coarse is not None else "")
                + f"{changes} at the re-solved points; at {where}): {value}.")


def _knots(knots: tuple[int, int]) -> str:
    """``24+8 knots``."""
    return f"{knots[0]}+{knots[1]} knots"


def _span(points: Sequence[PointError]) -> str:
    """``33-60 m/min`` (the speeds of ``points``)."""
    speeds = sorted(round(p.row.speed_m_min, 1) for p in points)
    return (f"{speeds[0]:g} m/min" if speeds[0] == speeds[-1] else
            f"{speeds[0]:g}-{speeds[-1]:g} m/min")


def _converged(rows: Sequence[SummaryRow]) -> dict[tuple[str, str, float], SummaryRow]:
    return {_key(r): r for r in rows if r.success and math.isfinite(r.cost)}


def _find(rows: dict[tuple[str, str, float], SummaryRow], row: SummaryRow
          ) -> SummaryRow | None:
    """``row``'s point among ``rows``: the same key, or for a speed-free optimum the same
    variant's (its speed differs between grids)."""
    key = _key(row)
    if row.speed_mode == "fixed":
        return rows.get(key)
    return next((c for k, c in rows.items() if k[:2] == key[:2]), None)


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
               check_dir: str | os.PathLike[str] | None = None,
               refine_dir: str | os.PathLike[str] | None = None) -> GridError | None:
    """The grid error of the sweep in ``sweep_dir`` (its ``rows``) against the check sweep in
    ``check_dir`` (default ``<sweep_dir>/check-grid``) and the refinement sweeps (default
    ``<sweep_dir>/refine-grid``, then ``refine-grid-2``, ... while they exist; or the one in
    ``refine_dir``); without a check sweep, the grid alone (no points). None when the sweep's
    grid is unknown (no ``sweep.json``). Only sweeps of the study's control model count."""
    grid = sweep_grid(sweep_dir)
    if grid is None:
        return None
    check = Path(check_dir) if check_dir is not None else Path(sweep_dir) / CHECK_DIR
    check_grid = sweep_grid(check)
    summary = check / SUMMARY_FILE
    if check_grid is None or not summary.exists() or check_grid[1] != grid[1]:
        return GridError(grid[0], grid[1], None, (), spacing=knot_spacing(sweep_dir))
    folders = ([Path(refine_dir)] if refine_dir is not None else
               [Path(sweep_dir) / refine_dir_name(k)
                for k in range(1, MAX_REFINE_LEVELS + 1)])
    levels: list[RefineLevel] = []
    for folder in folders:
        level_grid = sweep_grid(folder)
        if (level_grid is None or level_grid[1] != grid[1]
                or not (folder / SUMMARY_FILE).exists()):
            break
        levels.append(RefineLevel(tuple(read_summary(folder / SUMMARY_FILE)), level_grid[0],
                                  Path(os.path.relpath(folder, sweep_dir)).as_posix()))
    errors = GridError.compare(rows, read_summary(summary), knots=grid[0],
                               control_model=grid[1], check=check_grid[0],
                               refine_levels=levels)
    return replace(errors, spacing=knot_spacing(sweep_dir))


def knot_spacing(sweep_dir: str | os.PathLike[str]) -> str:
    """The knot spacing of a sweep's points (``uniform`` when ``sweep.json`` lacks it)."""
    try:
        settings = json.loads((Path(sweep_dir) / SETTINGS_FILE).read_text(encoding="utf-8"))
        return str(settings["settings"]["options"].get("knot_spacing", "uniform"))
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return "uniform"


__all__ = ["CHECK_DIR", "CHECK_KNOTS", "MAX_REFINE_LEVELS", "REFINE_DIR", "WITHIN", "GridError",
           "PointError", "RefineLevel", "check_knots", "first_order_factor", "grid_error",
           "knot_spacing", "refine_dir_name", "sweep_grid"]
