"""The sweep directory (``docs/outputs.md`` section 2) as the driver
(:mod:`gaitopt.study.driver`) finds and keeps it: the lock that lets one sweep run there at a
time, ``sweep.json`` written first or checked against the settings, the leftovers of atomic
writes interrupted by a kill, which points an earlier run finished (their gait files load,
converged and match the point's options and model) and the ``summary.csv`` of each
sub-sweep, rewritten atomically in grid order.
"""

from __future__ import annotations

import json
import math
from collections.abc import Collection, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from gaitopt.fileio import write_text_atomic
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.study.plan import (
    SETTINGS_FILE,
    SETTINGS_FORMAT,
    SweepSpec,
    settings_differences,
    settings_document,
    sweep_settings,
    with_option_defaults,
)
from gaitopt.study.summary import (
    GAITS_DIR,
    SUMMARY_FILE,
    SummaryError,
    SummaryRow,
    gait_relpath,
    read_summary,
    summary_row,
    variant_flags,
    write_summary,
)
from gaitopt.study.worker import gait_file_matches

LOCK_FILE = ".sweep.lock"


class SweepSettingsError(ValueError):
    """The sweep directory holds another sweep (or one is running there)."""


@contextmanager
def directory_lock(directory: Path) -> Iterator[None]:
    """Hold an exclusive lock on the sweep directory (released when the process ends, even
    by SIGKILL); raise :class:`SweepSettingsError` if another sweep holds it."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover  (not POSIX: no lock)
        yield
        return
    fh = open(directory / LOCK_FILE, "a")  # noqa: SIM115  (held for the whole sweep)
    try:
        try:
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise SweepSettingsError(f"{directory}: another sweep is running in this "
                                     "directory; wait for it or use another directory") from None
        yield
    finally:
        fh.close()


def prepare_directory(spec: SweepSpec, directory: Path) -> None:
    """Create the directory and write ``sweep.json``, or check that the one there has the
    same settings (:class:`SweepSettingsError` otherwise)."""
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / SETTINGS_FILE
    wanted = sweep_settings(spec)
    if path.exists():
        try:
            saved = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise SweepSettingsError(f"{path}: cannot read the sweep settings ({exc})") from None
        if not isinstance(saved, dict) or saved.get("format") != SETTINGS_FORMAT:
            raise SweepSettingsError(f"{path}: not a gaitopt sweep settings file")
        diffs = settings_differences(with_option_defaults(saved.get("settings", {})), wanted)
        if diffs:
            raise SweepSettingsError(
                f"{directory} holds a sweep made with other settings, so it cannot be resumed "
                f"with these; use another directory (-o) or the same settings. Differences: "
                + "; ".join(diffs))
        return
    if (directory / SUMMARY_FILE).exists() or (directory / GAITS_DIR).exists():
        raise SweepSettingsError(f"{directory} holds sweep results but no {SETTINGS_FILE}; "
                                 "use another directory")
    write_text_atomic(path, json.dumps(settings_document(spec), indent=2) + "\n")


def remove_leftovers(directory: Path) -> int:
    """Delete the temporary files of atomic writes interrupted by a kill (``.<name>.*.tmp``
    next to gait files and summaries); returns how many."""
    count = 0
    for path in directory.rglob(".*.tmp"):
        if path.is_file() and (".gait.json." in path.name or path.name.startswith(
                (f".{SUMMARY_FILE}.", f".{SETTINGS_FILE}."))):
            path.unlink(missing_ok=True)
            count += 1
    return count


@dataclass
class _Scan:
    kept: dict[str, SummaryRow] = field(default_factory=dict)
    old_failed: dict[str, SummaryRow] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def scan_directory(spec: SweepSpec, directory: Path) -> _Scan:
    """Which points an earlier run finished (see the module docstring), and the failed rows
    it recorded for the others."""
    scan = _Scan()
    for point in spec.points:
        path = directory / point.key
        if not path.exists():
            continue
        try:
            gait = Gait.load(path)
        except GaitFileError as exc:
            scan.notes.append(f"{point.key}: unreadable ({exc}); solving it again")
            continue
        why = gait_file_matches(gait, spec.model_of(point), spec.options(point))
        if why:
            scan.notes.append(f"{point.key}: not kept, {why}; solving it again")
            continue
        ankle, impulse = variant_flags(point.variant)
        scan.kept[point.key] = summary_row(gait, ankle=ankle, impulse=impulse,
                                           speed_mode=point.speed_mode, file=point.relfile)
    by_key = {p.key: p for p in spec.points}
    for sub in sorted({p.subdir for p in spec.points}):
        summary = directory / sub / SUMMARY_FILE
        if not summary.exists():
            continue
        try:
            rows = read_summary(summary)
        except SummaryError as exc:
            scan.notes.append(f"ignoring the earlier summary: {exc}")
            continue
        for row in rows:
            if row.success:
                continue
            speed = None if row.speed_mode == "free" else row.speed_m_s
            if speed is not None and not math.isfinite(speed):
                continue
            rel = gait_relpath(ankle=row.ankle, impulse=row.impulse, speed_mode=row.speed_mode,
                               speed_m_s=speed)
            key = f"{sub}/{rel}" if sub else rel
            if key in by_key and key not in scan.kept:
                scan.old_failed[key] = row
    return scan


def write_summaries(spec: SweepSpec, directory: Path, rows: dict[str, SummaryRow],
                    subdirs: Collection[str] | None = None) -> list[Path]:
    """Write ``summary.csv`` of each sub-sweep (``subdirs``: only these) from ``rows``, in
    grid order (variant, speed ascending, speed-free last)."""
    written = []
    for sub in sorted({p.subdir for p in spec.points}):
        if subdirs is not None and sub not in subdirs:
            continue
        ordered = [rows[p.key] for p in spec.points if p.subdir == sub and p.key in rows]
        written.append(write_summary(directory / sub / SUMMARY_FILE, ordered))
    return written
