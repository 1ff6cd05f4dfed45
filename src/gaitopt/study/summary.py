"""The sweep summary table (``summary.csv``) and the sweep directory layout.

A sweep directory holds (see ``docs/outputs.md``)::

    <sweep>/summary.csv                                    one row per solved point
    <sweep>/gaits/<variant>/speed-012.00m_min.gait.json    fixed-speed points
    <sweep>/gaits/<variant>/speed-free.gait.json           the speed-free (optimal) walk

Variants are the four combinations of ankle torques and liftoff impulse:
``ankle+impulse``, ``ankle``, ``impulse``, ``plain``. Columns of ``summary.csv``, in order, are
:data:`SUMMARY_COLUMNS`; unknown values (a failed free-speed solve has no speed) are empty
cells, read back as NaN; ``file`` is the gait file's path relative to the sweep directory,
empty when no gait file was written.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from gaitopt.fileio import write_text_atomic
from gaitopt.gait.record.file import Gait

SpeedMode = Literal["fixed", "free"]

VARIANTS: tuple[str, ...] = ("ankle+impulse", "ankle", "impulse", "plain")
SUMMARY_FILE = "summary.csv"
GAITS_DIR = "gaits"
SUMMARY_COLUMNS: tuple[str, ...] = (
    "variant", "ankle", "impulse", "speed_mode", "speed_m_s", "speed_m_min", "step_length",
    "step_time", "cost", "status", "success", "iterations", "wall_time_s", "file")
_FLOAT_COLUMNS = ("speed_m_s", "speed_m_min", "step_length", "step_time", "cost", "wall_time_s")


class SummaryError(ValueError):
    """A summary table is invalid: names the file, the line and the column."""


def variant_name(*, ankle: bool, impulse: bool) -> str:
    """The variant's name: ankle torques on/off x liftoff impulse on/off."""
    if ankle:
        return "ankle+impulse" if impulse else "ankle"
    return "impulse" if impulse else "plain"


def variant_flags(name: str) -> tuple[bool, bool]:
    """``(ankle, impulse)`` of a variant name."""
    if name not in VARIANTS:
        raise ValueError(f"unknown variant {name!r}; expected one of {', '.join(VARIANTS)}")
    return ("ankle" in name, "impulse" in name)


def gait_relpath(*, ankle: bool, impulse: bool, speed_mode: SpeedMode,
                 speed_m_s: float | None = None) -> str:
    """Where a sweep point's gait file goes, relative to the sweep directory.

    ``gaits/<variant>/speed-free.gait.json`` or ``gaits/<variant>/speed-012.00m_min.gait.json``
    (the fixed speed in m/min with two decimals).
    """
    folder = f"{GAITS_DIR}/{variant_name(ankle=ankle, impulse=impulse)}"
    if speed_mode == "free":
        return f"{folder}/speed-free.gait.json"
    if speed_mode != "fixed" or speed_m_s is None or not speed_m_s >= 0:
        raise ValueError("gait_relpath: a fixed speed_mode needs speed_m_s >= 0; "
                         f"got speed_mode={speed_mode!r}, speed_m_s={speed_m_s!r}")
    return f"{folder}/speed-{speed_m_s * 60.0:06.2f}m_min.gait.json"


@dataclass(frozen=True, kw_only=True)
class SummaryRow:
    """One sweep point. Speeds in m/s and m/min, lengths m, times s; NaN where unknown."""

    variant: str
    ankle: bool
    impulse: bool
    speed_mode: SpeedMode
    speed_m_s: float
    speed_m_min: float
    step_length: float
    step_time: float
    cost: float
    status: str
    success: bool
    iterations: int
    wall_time_s: float
    file: str

    def __post_init__(self) -> None:
        if self.variant != variant_name(ankle=self.ankle, impulse=self.impulse):
            raise ValueError(f"variant {self.variant!r} does not match ankle={self.ankle}, "
                             f"impulse={self.impulse}")
        if self.speed_mode not in ("fixed", "free"):
            raise ValueError(f"speed_mode: expected 'fixed' or 'free', got {self.speed_mode!r}")

    def as_csv_dict(self) -> dict[str, str]:
        return csv_cells(self, SUMMARY_COLUMNS)


def summary_row(gait: Gait, *, ankle: bool, impulse: bool, speed_mode: SpeedMode,
                file: str) -> SummaryRow:
    """The summary row of a solved gait (``file``: its path relative to the sweep dir)."""
    return SummaryRow(
        variant=variant_name(ankle=ankle, impulse=impulse), ankle=ankle, impulse=impulse,
        speed_mode=speed_mode, speed_m_s=gait.speed, speed_m_min=gait.speed * 60.0,
        step_length=gait.step_length, step_time=gait.step_time, cost=gait.cost_value,
        status=gait.status, success=gait.success, iterations=int(gait.solver["iterations"]),
        wall_time_s=float(gait.solver["wall_time_s"]), file=file)


def failed_row(*, ankle: bool, impulse: bool, speed_mode: SpeedMode, status: str,
               speed_m_s: float = math.nan, iterations: int = 0,
               wall_time_s: float = math.nan) -> SummaryRow:
    """The row of a point whose solve failed and wrote no gait file."""
    return SummaryRow(
        variant=variant_name(ankle=ankle, impulse=impulse), ankle=ankle, impulse=impulse,
        speed_mode=speed_mode, speed_m_s=speed_m_s, speed_m_min=speed_m_s * 60.0,
        step_length=math.nan, step_time=math.nan, cost=math.nan, status=status, success=False,
        iterations=iterations, wall_time_s=wall_time_s, file="")


def csv_cells(row: Any, columns: Sequence[str]) -> dict[str, str]:
    """The CSV cells of ``row``'s attributes ``columns``: booleans ``true``/``false``, floats
    by ``repr`` (exact round trip) with NaN as an empty cell, anything else by ``str``."""
    out: dict[str, str] = {}
    for col in columns:
        value: Any = getattr(row, col)
        if isinstance(value, bool):
            out[col] = "true" if value else "false"
        elif isinstance(value, float):
            out[col] = "" if math.isnan(value) else repr(value)
        else:
            out[col] = str(value)
    return out


def csv_text(rows: Iterable[Any], columns: Sequence[str]) -> str:
    """CSV text (``\\n`` line ends) of rows that have ``as_csv_dict()``, header ``columns``."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(columns), lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow(row.as_csv_dict())
    return buffer.getvalue()


def summary_csv(rows: Iterable[SummaryRow]) -> str:
    """The CSV text of the rows (header: :data:`SUMMARY_COLUMNS`)."""
    return csv_text(rows, SUMMARY_COLUMNS)


def write_summary(path: str | os.PathLike[str], rows: Iterable[SummaryRow]) -> Path:
    """Write ``summary.csv`` atomically."""
    write_text_atomic(path, summary_csv(rows))
    return Path(path)


def read_summary(path: str | os.PathLike[str]) -> list[SummaryRow]:
    """Read and validate ``summary.csv``; errors name the file, line and column."""
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise SummaryError(f"{source}: cannot read the summary table ({exc})") from None
    return parse_summary(text, source=source)


def parse_summary(text: str, *, source: str = "<summary>") -> list[SummaryRow]:
    reader = csv.DictReader(io.StringIO(text))
    missing = [c for c in SUMMARY_COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise SummaryError(f"{source}: line 1: missing columns {', '.join(missing)} "
                           f"(expected {', '.join(SUMMARY_COLUMNS)})")
    rows = []
    for line, raw in enumerate(reader, start=2):
        rows.append(_row(raw, f"{source}: line {line}"))
    return rows


def _row(raw: dict[str, str], where: str) -> SummaryRow:
    def boolean(col: str) -> bool:
        value = (raw[col] or "").strip().lower()
        if value not in ("true", "false", "1", "0"):
            raise SummaryError(f"{where}: column {col}: expected true or false, got {value!r}")
        return value in ("true", "1")

    def number(col: str) -> float:
        value = (raw[col] or "").strip()
        if value == "":
            return math.nan
        try:
            return float(value)
        except ValueError:
            raise SummaryError(f"{where}: column {col}: expected a number, got {value!r}") from None

    fields: dict[str, Any] = {c: number(c) for c in _FLOAT_COLUMNS}
    iterations = number("iterations")
    fields["iterations"] = 0 if math.isnan(iterations) else int(iterations)
    try:
        return SummaryRow(variant=raw["variant"], ankle=boolean("ankle"),
                          impulse=boolean("impulse"),
                          speed_mode=raw["speed_mode"],  # type: ignore[arg-type]
                          status=raw["status"] or "", success=boolean("success"),
                          file=raw["file"] or "", **fields)
    except ValueError as exc:
        if isinstance(exc, SummaryError):
            raise
        raise SummaryError(f"{where}: {exc}") from None


def rows_of(rows: Sequence[SummaryRow], variant: str, *, speed_mode: SpeedMode | None = None,
            success: bool | None = True) -> list[SummaryRow]:
    """The rows of one variant (optionally one speed mode / success), sorted by speed."""
    out = [r for r in rows if r.variant == variant
           and (speed_mode is None or r.speed_mode == speed_mode)
           and (success is None or r.success == success)]
    return sorted(out, key=lambda r: (math.inf if math.isnan(r.speed_m_s) else r.speed_m_s))
