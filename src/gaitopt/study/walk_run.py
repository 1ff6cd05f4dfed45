"""The walk-run study: at each speed of a grid, the optimal walk and the optimal run of a model
under one cost, which is cheaper, and where the cheaper gait changes (docs/running.md).

For every model and cost asked for, one sweep (:mod:`gaitopt.study.plan`) per *branch*, a
contact sequence the model allows:

* ``walk``: the paper's walk (single support 0.85 of the step, then double support; ankle
  torques and the liftoff impulse on), for a model with one contact point per leg;
* ``heel-toe``: the heel-toe walk instead, for a model with feet (heel and toe points);
* ``walk-single-support``: the walk without double support (the trailing leg leaves at heel
  strike, ``single_support_fraction = 1``; ankle torques on, no liftoff to push from), for a
  model with one contact point per leg;
* ``run``: stance on one leg, then a flight (stance share free, no impulse;
  docs/running.md); on feet a toe run.

Every branch is solved at every fixed speed of the grid with the step length free, by
continuation in speed from the point nearest the branch's default speed, and every point also
solves its check grid (:attr:`~gaitopt.study.plan.SweepSpec.check_grid`), so each converged
gait carries its cost's grid error estimate ``solver.accuracy.cost_error``. The sweeps are
ordinary sweep directories: written atomically point by point, resumable, refused when made
with other settings::

    DIR/walk_run.json                        the study's settings (written first)
    DIR/<model>/<cost>/<branch>/sweep.json, summary.csv, gaits/<variant>/...   each sweep
    DIR/walk_run.csv                         one row per (model, cost, branch, speed)
    DIR/transitions.csv                      one row per (model, cost): the transition
    DIR/report/report.html, walk_run.png     the figure, the tables and the findings

A failed point is a row with ``success = false`` and its status; it has no cost and plays no
part in the transition (:mod:`gaitopt.study.transition`), which compares at each speed the
cheapest converged walking branch with the run. ``cheapest`` marks, at each speed, the
converged branch of least cost.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from gaitopt import __version__
from gaitopt.fileio import write_text_atomic
from gaitopt.gait.options.gait_options import KNOT_SPACINGS, GaitOptions, KnotSpacing
from gaitopt.gait.options.model_defaults import default_gait
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.robot.model import RobotModel
from gaitopt.study.cost_study import STUDY_MAX_ITER
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, SummaryError, csv_cells, csv_text, read_summary
from gaitopt.study.transition import Transition, froude_number, walk_run_transition

WALK_RUN_FILE = "walk_run.json"
WALK_RUN_FORMAT = "gaitopt.walk-run-study"
TABLE_FILE = "walk_run.csv"
TRANSITIONS_FILE = "transitions.csv"
COSTS = ("paper", "metabolic")
#: Default speed grids (m/min) by the model's walk: the five-link biped's walk fails above
#: 90-120 m/min and its run from 150 m/min (docs/running.md); a model with feet walks heel to
#: toe at people's speeds. Chosen and timed in docs/running.md ("The walk-run study").
DEFAULT_SPEEDS_M_MIN: dict[str, tuple[float, ...]] = {
    "walk": (15.0, 30.0, 45.0, 60.0, 75.0, 90.0, 105.0, 120.0, 135.0, 150.0),
    "heel-toe": (30.0, 60.0, 90.0, 120.0, 150.0),
}
#: ... and for the metabolic cost on feet: minutes per solve (measured: the heel-toe walk at
#: 60 m/min, cold, 580 s and 3153 IPOPT iterations; a warm one with its check grid more than
#: 10 min), so two speeds around the transition under the paper's cost and people's.
DEFAULT_SPEEDS_M_MIN_BY_COST: dict[tuple[str, str], tuple[float, ...]] = {
    ("heel-toe", "metabolic"): (60.0, 120.0),
}


class WalkRunStudyError(ValueError):
    """A walk-run study request or its files are invalid (names the setting or the file)."""


@dataclass(frozen=True)
class Branch:
    """One contact sequence of the study: its ``name`` (the folder), whether it is a walk or
    a run (``kind``), its built-in ``gait``, the single-support fraction of its sweep (for a
    run the first guess of its free stance share) and the sweep variant (ankle torques and
    liftoff impulse, :data:`gaitopt.study.summary.VARIANTS`)."""

    name: str
    kind: str
    gait: str
    single_support: float
    variant: str

    @property
    def label(self) -> str:
        return {"walk": "walk", "heel-toe": "heel-toe walk",
                "walk-single-support": "walk without double support",
                "run": "run"}[self.name]


WALK = Branch("walk", "walk", "walk", 0.85, "ankle+impulse")
HEEL_TOE = Branch("heel-toe", "walk", "heel-toe", 0.85, "ankle+impulse")
SINGLE_SUPPORT_WALK = Branch("walk-single-support", "walk", "walk", 1.0, "ankle")
RUN = Branch("run", "run", "run", 0.9, "ankle")


def branches_of(model: RobotModel) -> tuple[Branch, ...]:
    """The branches ``model`` allows (module docstring): the walk, the walk without double
    support and the run with one contact point per leg; the heel-toe walk and the (toe) run
    on feet."""
    if default_gait(model) == "heel-toe":
        return (HEEL_TOE, RUN)
    return (WALK, SINGLE_SUPPORT_WALK, RUN)


def leg_length_of(model: RobotModel) -> float:
    """The leg length (m) of the Froude numbers: the hip's height above the lowest contact
    point, standing (:func:`gaitopt.gait.options.model_scale.leg_length`)."""
    return model_scale(model).leg_length


@dataclass(frozen=True, kw_only=True)
class WalkRunSpec:
    """What the walk-run study solves (SI units).

    ``models``; ``costs`` a subset of :data:`COSTS` (the paper's ``int u'u dt / L`` and the
    metabolic cost of transport at the default resting power); ``speeds`` (m/s, ascending)
    the grid of every model and cost, or None: by each model's walk and the cost
    (:meth:`speeds_of`);
    ``knots`` per phase of every branch (first phase, the others), or None: each branch's
    default (16 + 6 for two phases, 24 + 16 for the heel-toe walk); ``knot_spacing`` that of
    every solve.
    """

    models: tuple[RobotModel, ...]
    costs: tuple[str, ...] = COSTS
    speeds: tuple[float, ...] | None = None
    knots: tuple[int, int] | None = None
    knot_spacing: KnotSpacing = "cosine"

    def __post_init__(self) -> None:
        if not self.models:
            raise WalkRunStudyError("models: at least one model is needed")
        names = [m.name for m in self.models]
        if len(set(names)) != len(names):
            raise WalkRunStudyError(f"models: two models share a name ({', '.join(names)}); "
                                    "each model's results go to a folder named after it")
        for name in names:
            if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.+-]*", name):
                raise WalkRunStudyError(f"models: the name {name!r} cannot name a folder "
                                        "(letters, digits, '_', '.', '+', '-')")
        if (not self.costs or len(set(self.costs)) != len(self.costs)
                or any(c not in COSTS for c in self.costs)):
            raise WalkRunStudyError(f"costs: {', '.join(self.costs) or 'none'}; allowed: each "
                                    f"of {', '.join(COSTS)} at most once, at least one")
        if self.speeds is not None:
            if len(self.speeds) < 2:
                raise WalkRunStudyError("speeds: at least two speeds (a transition lies "
                                        "between two)")
            if any(not (math.isfinite(v) and v > 0) for v in self.speeds) or any(
                    b <= a for a, b in zip(self.speeds, self.speeds[1:], strict=False)):
                raise WalkRunStudyError("speeds: positive, finite and strictly ascending")
        if self.knots is not None and not (len(self.knots) == 2
                                           and all(k >= 2 for k in self.knots)):
            raise WalkRunStudyError(f"knots: {self.knots!r}; allowed: two counts >= 2 "
                                    "(first phase, the others)")
        if self.knot_spacing not in KNOT_SPACINGS:
            raise WalkRunStudyError(f"knot_spacing = {self.knot_spacing!r}: must be one of "
                                    f"{', '.join(KNOT_SPACINGS)}")

    def speeds_of(self, model: RobotModel, cost: str) -> tuple[float, ...]:
        """The speed grid (m/s) of ``model`` under ``cost``: ``speeds``, or the default of its
        walk and the cost (:data:`DEFAULT_SPEEDS_M_MIN_BY_COST`, else
        :data:`DEFAULT_SPEEDS_M_MIN`)."""
        if self.speeds is not None:
            return self.speeds
        gait = default_gait(model)
        grid = DEFAULT_SPEEDS_M_MIN_BY_COST.get((gait, cost), DEFAULT_SPEEDS_M_MIN[gait])
        return tuple(v / 60.0 for v in grid)

    def sweep_of(self, model: RobotModel, cost: str, branch: Branch) -> SweepSpec:
        """The sweep of one (model, cost, branch): every speed of the grid, step free."""
        extra: dict[str, Any] = {} if self.knots is None else {"knots": self.knots}
        base = GaitOptions(gait=branch.gait, cost=cost,  # type: ignore[arg-type]
                           knot_spacing=self.knot_spacing, max_iter=STUDY_MAX_ITER, **extra)
        return SweepSpec(model=model, speeds=self.speeds_of(model, cost),
                         variants=(branch.variant,),
                         free_speed=False, single_support=(branch.single_support,), base=base,
                         check_grid=True)

    def sweeps(self) -> tuple[tuple[str, RobotModel, str, Branch, SweepSpec], ...]:
        """Every sweep as ``(folder relative to the study directory, model, cost, branch,
        spec)``, model by model, cost by cost."""
        return tuple((f"{m.name}/{c}/{b.name}", m, c, b, self.sweep_of(m, c, b))
                     for m in self.models for c in self.costs for b in branches_of(m))

    def settings(self) -> dict[str, Any]:
        """The study's settings (``walk_run.json``)."""
        return {"format": WALK_RUN_FORMAT, "version": 1, "gaitopt_version": __version__,
                "models": [{"name": m.name, "content_hash": m.content_hash(),
                            "leg_length_m": leg_length_of(m),
                            "speeds_m_min": {c: [round(v * 60.0, 9)
                                                 for v in self.speeds_of(m, c)]
                                             for c in self.costs},
                            "branches": [b.name for b in branches_of(m)]}
                           for m in self.models],
                "costs": list(self.costs),
                "knots": None if self.knots is None else list(self.knots),
                "knot_spacing": self.knot_spacing, "max_iter": STUDY_MAX_ITER}


def write_settings(spec: WalkRunSpec, directory: str | os.PathLike[str]) -> Path:
    """Write ``walk_run.json`` atomically (it marks the folder as a walk-run study)."""
    path = Path(directory) / WALK_RUN_FILE
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(spec.settings(), indent=2) + "\n")
    return path


# -- the table ----------------------------------------------------------------------------------

TABLE_COLUMNS: tuple[str, ...] = (
    "model", "cost", "branch", "kind", "speed_m_min", "froude", "success", "status",
    "cost_value", "cost_error", "step_length", "step_time", "first_phase_share", "cheapest",
    "file")


@dataclass(frozen=True, kw_only=True)
class WalkRunRow:
    """One point of the study: speed (m/min), its Froude number, the cost's value and its
    grid error estimate (``solver.accuracy.cost_error``: ``J(grid) - J(limit)``, the cost's
    unit; NaN when unknown), step length (m), step time (s), the first phase's share of the
    step (``single_support_time / step_time``: the walk's single support, the run's stance,
    the heel-toe walk's foot-flat phase; NaN if the gait has no such parameter), whether it
    is the cheapest converged branch at its speed, and the gait file relative to the study
    directory (empty for a failed point). NaN where the solve failed."""

    model: str
    cost: str
    branch: str
    kind: str
    speed_m_min: float
    froude: float
    success: bool
    status: str
    cost_value: float = math.nan
    cost_error: float = math.nan
    step_length: float = math.nan
    step_time: float = math.nan
    first_phase_share: float = math.nan
    cheapest: bool = False
    file: str = ""

    def as_csv_dict(self) -> dict[str, str]:
        return csv_cells(self, TABLE_COLUMNS)


def _number(x: Any) -> float:
    return float(x) if isinstance(x, int | float) and not isinstance(x, bool) else math.nan


def point_row(model: RobotModel, cost: str, branch: Branch, speed: float, subdir: str,
              summary: dict[str, Any], top: Path) -> WalkRunRow:
    """The row of one grid point from its summary row (``summary``: the sweep's row as a
    dict, or empty when the point was never solved) and its gait file."""
    common: dict[str, Any] = {"model": model.name, "cost": cost, "branch": branch.name,
              "kind": branch.kind,
              "speed_m_min": speed * 60.0,
              "froude": froude_number(speed, leg_length_of(model), model_scale(model).gravity)}
    if not summary:
        return WalkRunRow(**common, success=False, status="not solved")
    if not summary["success"]:
        return WalkRunRow(**common, success=False, status=summary["status"])
    rel = f"{subdir}/{summary['file']}"
    try:
        gait = Gait.load(top / rel)
    except GaitFileError as exc:
        return WalkRunRow(**common, success=False, status=f"unreadable gait file: {exc}")
    accuracy = gait.solver.get("accuracy") or {}
    single = _number(gait.parameters.get("single_support_time"))
    return WalkRunRow(**common, success=gait.success, status=gait.status,
                      cost_value=gait.cost_value,
                      cost_error=_number(accuracy.get("cost_error")),
                      step_length=gait.step_length, step_time=gait.step_time,
                      first_phase_share=single / gait.step_time, file=rel)


def mark_cheapest(rows: Sequence[WalkRunRow]) -> list[WalkRunRow]:
    """``rows`` with ``cheapest`` set on the converged row of least cost of each (model,
    cost, speed) (none where no branch converged)."""
    best: dict[tuple[str, str, float], WalkRunRow] = {}
    for r in rows:
        key = (r.model, r.cost, round(r.speed_m_min, 6))
        if r.success and math.isfinite(r.cost_value) and (
                key not in best or r.cost_value < best[key].cost_value):
            best[key] = r
    chosen = {id(r) for r in best.values()}
    return [WalkRunRow(**{**r.__dict__, "cheapest": id(r) in chosen}) for r in rows]


def collect_rows(spec: WalkRunSpec, directory: str | os.PathLike[str]) -> list[WalkRunRow]:
    """Every (model, cost, branch, speed) of the study from its sweeps' summaries and gait
    files, the cheapest marked; a point that no sweep has solved is ``not solved``."""
    top = Path(directory)
    rows = []
    for subdir, model, cost, branch, sweep in spec.sweeps():
        try:
            summary = read_summary(top / subdir / SUMMARY_FILE)
        except SummaryError:
            summary = []
        by_speed = {f"{r.speed_m_min:.6f}": r.__dict__ for r in summary
                    if r.speed_mode == "fixed"}
        for v in sweep.speeds:
            rows.append(point_row(model, cost, branch, v, subdir,
                                  by_speed.get(f"{v * 60.0:.6f}", {}), top))
    return mark_cheapest(rows)


def write_table(directory: str | os.PathLike[str], rows: Sequence[WalkRunRow]) -> Path:
    """Write ``walk_run.csv`` atomically."""
    path = Path(directory) / TABLE_FILE
    write_text_atomic(path, csv_text(rows, TABLE_COLUMNS))
    return path


def read_table(path: str | os.PathLike[str]) -> list[WalkRunRow]:
    """Read ``walk_run.csv`` (errors name the file, the line and the column)."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise WalkRunStudyError(f"{path}: cannot read the walk-run table ({exc})") from None
    reader = csv.DictReader(io.StringIO(text))
    missing = [c for c in TABLE_COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise WalkRunStudyError(f"{path}: line 1: missing columns {', '.join(missing)}")
    rows = []
    floats = ("speed_m_min", "froude", "cost_value", "cost_error", "step_length", "step_time",
              "first_phase_share")
    for line, raw in enumerate(reader, start=2):
        fields: dict[str, Any] = {}
        for col in TABLE_COLUMNS:
            cell = (raw[col] or "").strip()
            if col in floats:
                try:
                    fields[col] = float(cell) if cell else math.nan
                except ValueError:
                    raise WalkRunStudyError(f"{path}: line {line}: column {col}: expected a "
                                            f"number, got {cell!r}") from None
            elif col in ("success", "cheapest"):
                if cell not in ("true", "false"):
                    raise WalkRunStudyError(f"{path}: line {line}: column {col}: expected "
                                            f"true or false, got {cell!r}")
                fields[col] = cell == "true"
            else:
                fields[col] = raw[col] or ""
        rows.append(WalkRunRow(**fields))
    return rows


# -- the transitions ----------------------------------------------------------------------------

TRANSITION_COLUMNS: tuple[str, ...] = (
    "model", "cost", "kind", "bracket_low_m_min", "bracket_high_m_min", "speed_m_min",
    "low_m_min", "high_m_min", "froude", "froude_low", "froude_high", "leg_length_m",
    "leaves_bracket", "unknown_errors", "changes", "speeds_compared", "speeds_skipped")


@dataclass(frozen=True, kw_only=True)
class TransitionRow:
    """The walk-run transition of one (model, cost): :class:`~gaitopt.study.transition.
    Transition` in m/min, with the Froude numbers ``v^2 / (g l)`` of the crossing and its
    grid-error interval on the model's leg length ``l`` (:func:`leg_length_of`)."""

    model: str
    cost: str
    transition: Transition
    leg_length_m: float
    gravity: float = 9.81

    def _fr(self, v: float) -> float:
        return froude_number(v, self.leg_length_m, self.gravity)

    def as_csv_dict(self) -> dict[str, str]:
        t = self.transition
        values = {
            "model": self.model, "cost": self.cost, "kind": t.kind,
            "bracket_low_m_min": t.bracket[0] * 60.0, "bracket_high_m_min": t.bracket[1] * 60.0,
            "speed_m_min": t.speed * 60.0, "low_m_min": t.interval[0] * 60.0,
            "high_m_min": t.interval[1] * 60.0, "froude": self._fr(t.speed),
            "froude_low": self._fr(t.interval[0]), "froude_high": self._fr(t.interval[1]),
            "leg_length_m": self.leg_length_m,
            "leaves_bracket": t.leaves_bracket, "unknown_errors": t.unknown_errors,
            "changes": t.changes,
            "speeds_compared": " ".join(f"{v * 60.0:g}" for v in t.speeds),
            "speeds_skipped": " ".join(f"{v * 60.0:g}" for v in t.skipped)}
        return csv_cells(SimpleNamespace(**values), TRANSITION_COLUMNS)

    @property
    def froude(self) -> float:
        return self._fr(self.transition.speed)


def cost_curves(rows: Sequence[WalkRunRow], model: str, cost: str
                ) -> tuple[list[float], list[float], list[float], list[float], list[float]]:
    """The speeds (m/s, ascending) of one (model, cost), and at each the cheapest converged
    walking branch's cost and grid error, and the run's (NaN where none converged)."""
    mine = [r for r in rows if r.model == model and r.cost == cost]
    speeds = sorted({round(r.speed_m_min, 6) for r in mine})
    walk, walk_e, run, run_e = [], [], [], []
    for v in speeds:
        at = [r for r in mine if round(r.speed_m_min, 6) == v and r.success
              and math.isfinite(r.cost_value)]
        walks = sorted((r for r in at if r.kind == "walk"), key=lambda r: r.cost_value)
        runs = [r for r in at if r.kind == "run"]
        walk.append(walks[0].cost_value if walks else math.nan)
        walk_e.append(walks[0].cost_error if walks else math.nan)
        run.append(runs[0].cost_value if runs else math.nan)
        run_e.append(runs[0].cost_error if runs else math.nan)
    return [v / 60.0 for v in speeds], walk, walk_e, run, run_e


def transitions(spec: WalkRunSpec, rows: Sequence[WalkRunRow]) -> list[TransitionRow]:
    """The transition of every (model, cost) of ``spec`` from ``rows``."""
    out = []
    for model in spec.models:
        for cost in spec.costs:
            speeds, walk, walk_e, run, run_e = cost_curves(rows, model.name, cost)
            t = walk_run_transition(speeds, walk, run, walk_error=walk_e, run_error=run_e)
            out.append(TransitionRow(model=model.name, cost=cost, transition=t,
                                     leg_length_m=leg_length_of(model),
                                     gravity=model_scale(model).gravity))
    return out


def write_transitions(directory: str | os.PathLike[str], rows: Sequence[TransitionRow]) -> Path:
    """Write ``transitions.csv`` atomically."""
    path = Path(directory) / TRANSITIONS_FILE
    write_text_atomic(path, csv_text(rows, TRANSITION_COLUMNS))
    return path
