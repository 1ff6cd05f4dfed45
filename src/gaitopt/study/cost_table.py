"""The cost study's results table: one row per (model, case), the speed-free optimum, and its
file ``costs.csv`` (:mod:`gaitopt.study.cost_study` fills it; :mod:`gaitopt.viz.cost_report`
and :mod:`gaitopt.study.cost_findings` read it).

Columns (:data:`COST_COLUMNS`): the model, its formulation, the case (``paper``, ``work``,
``metabolic-rest-<P>``), the cost and resting power (W/kg), whether the solve converged and
its status, speed (m/min), step length (m), step time (s), the cost's value (its own units,
docs/costs.md), the distance from human walking (:func:`human_distance`), which start won and
the other start's cost, the gait file relative to the study directory, and the accuracy pass's
outcome (:mod:`gaitopt.study.cost_accuracy`): the largest relative error estimate, what it
estimates (``cost``, ``speed``, ``step_length``), the knots of the reported grid (``24+16``
for two phases, by phase) and whether the estimate is within the study's accuracy. NaN and
None are written as empty cells.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from gaitopt.fileio import write_text_atomic
from gaitopt.study.findings import HUMAN_OPTIMAL_SPEED_M_MIN, HUMAN_STEP_LENGTH
from gaitopt.study.summary import csv_cells, csv_text

COST_TABLE_FILE = "costs.csv"
COST_COLUMNS: tuple[str, ...] = (
    "model", "formulation", "case", "cost", "resting_power", "success", "status",
    "speed_m_min", "step_length", "step_time", "cost_value", "human_distance", "start",
    "other_cost_value", "file", "estimate", "estimate_of", "knots", "within_accuracy",
    "smoothing_share")
#: Columns added later (2026-12-03): a table without them reads with them empty.
OPTIONAL_COLUMNS: tuple[str, ...] = ("estimate", "estimate_of", "knots", "within_accuracy",
                                     "smoothing_share")


class CostStudyError(ValueError):
    """A cost study request or its files are invalid (names the setting or the file)."""


def human_distance(speed_m_min: float, step_length: float) -> float:
    """``sqrt((v / 80 - 1)^2 + (L / 0.75 - 1)^2)``: 0 at people's walk
    (:mod:`gaitopt.study.cost_study`)."""
    return math.hypot(speed_m_min / HUMAN_OPTIMAL_SPEED_M_MIN - 1.0,
                      step_length / HUMAN_STEP_LENGTH - 1.0)


@dataclass(frozen=True, kw_only=True)
class CostRow:
    """The speed-free optimum of one (model, case): speed m/min, step m, step time s, the
    cost's value (its own units, docs/costs.md), NaN where the solve failed; ``file`` the gait
    file relative to the study directory; ``smoothing_share`` the share of the cost that is
    the smoothing of its positive parts (:func:`gaitopt.gait.formulations.cost.smoothing_record`;
    NaN for the paper's cost or where unknown)."""

    model: str
    formulation: str
    case: str
    cost: str
    resting_power: float
    success: bool
    status: str
    speed_m_min: float
    step_length: float
    step_time: float
    cost_value: float
    file: str
    start: str = ""
    other_cost_value: float = math.nan
    estimate: float = math.nan
    estimate_of: str = ""
    knots: str = ""
    within_accuracy: bool | None = None
    smoothing_share: float = math.nan
    human_distance: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "human_distance",
                           human_distance(self.speed_m_min, self.step_length)
                           if self.success else math.nan)

    def as_csv_dict(self) -> dict[str, str]:
        cells = csv_cells(self, COST_COLUMNS)
        if self.within_accuracy is None:
            cells["within_accuracy"] = ""
        return cells


def cost_table_csv(rows: Sequence[CostRow]) -> str:
    """The CSV text of the rows (header: :data:`COST_COLUMNS`)."""
    return csv_text(rows, COST_COLUMNS)


def write_cost_table(directory: str | os.PathLike[str], rows: Sequence[CostRow]) -> Path:
    """Write ``costs.csv`` atomically."""
    path = Path(directory) / COST_TABLE_FILE
    write_text_atomic(path, cost_table_csv(rows))
    return path


def read_cost_table(path: str | os.PathLike[str]) -> list[CostRow]:
    """Read ``costs.csv``; errors name the file, the line and the column."""
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise CostStudyError(f"{source}: cannot read the cost table ({exc})") from None
    reader = csv.DictReader(io.StringIO(text))
    missing = [c for c in COST_COLUMNS
               if c not in (reader.fieldnames or []) and c not in OPTIONAL_COLUMNS]
    if missing:
        raise CostStudyError(f"{source}: line 1: missing columns {', '.join(missing)}")
    rows = []
    for line, raw in enumerate(reader, start=2):
        def number(col: str, raw: dict[str, str] = raw, line: int = line) -> float:
            value = (raw[col] or "").strip()
            try:
                return float(value) if value else math.nan
            except ValueError:
                raise CostStudyError(f"{source}: line {line}: column {col}: expected a "
                                     f"number, got {value!r}") from None

        def flag(col: str, raw: dict[str, str] = raw, line: int = line,
                 empty: bool = False) -> bool | None:
            value = (raw.get(col) or "").strip().lower()
            if value in ("true", "false"):
                return value == "true"
            if empty and not value:
                return None
            raise CostStudyError(f"{source}: line {line}: column {col}: expected true or "
                                 f"false{' or empty' if empty else ''}, got {value!r}")

        success = flag("success")
        rows.append(CostRow(model=raw["model"], formulation=raw["formulation"],
                            case=raw["case"], cost=raw["cost"],
                            resting_power=number("resting_power"), success=bool(success),
                            status=raw["status"] or "", speed_m_min=number("speed_m_min"),
                            step_length=number("step_length"), step_time=number("step_time"),
                            cost_value=number("cost_value"), file=raw["file"] or "",
                            start=raw["start"] or "",
                            other_cost_value=number("other_cost_value"),
                            estimate=number("estimate") if "estimate" in raw else math.nan,
                            estimate_of=raw.get("estimate_of") or "",
                            knots=raw.get("knots") or "",
                            within_accuracy=flag("within_accuracy", empty=True),
                            smoothing_share=(number("smoothing_share")
                                             if "smoothing_share" in raw else math.nan)))
    return rows
