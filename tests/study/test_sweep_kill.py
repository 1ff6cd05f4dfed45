"""Killing a sweep (SIGKILL, driver and workers) loses no finished point and corrupts no file;
rerunning the same command resumes without recomputing what was finished."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from gaitopt.gait.record.file import Gait
from gaitopt.study.summary import SUMMARY_FILE, SummaryError, read_summary

SRC = Path(__file__).resolve().parents[2] / "src"
ARGS = ["sweep", "--speeds", "6:18:3", "--variants", "plain", "--no-free", "--workers", "1"]


def gaitopt(*args: str, **kw: object) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])])}
    return subprocess.Popen([sys.executable, "-m", "gaitopt", *args], env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True, **kw)  # type: ignore[call-overload]


def solved(folder: Path) -> int:
    try:
        return sum(r.success for r in read_summary(folder / SUMMARY_FILE))
    except (SummaryError, OSError):
        return 0


def test_kill_then_resume_keeps_every_finished_point(tmp_path: Path) -> None:
    folder = tmp_path / "sweep"
    first = gaitopt(*ARGS, "-o", str(folder))
    deadline = time.monotonic() + 240
    while solved(folder) < 2 and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert first.poll() is None, f"the sweep ended before it could be killed:\n{first.stdout}"
    os.killpg(first.pid, signal.SIGKILL)  # the driver and its worker processes
    first.wait()
    out = first.stdout.read() if first.stdout else ""

    # after the kill: the summary and every gait file are whole; finished points are there
    rows = read_summary(folder / SUMMARY_FILE)
    finished = {r.file for r in rows if r.success}
    assert len(finished) >= 2, out
    files = sorted(folder.rglob("*.gait.json"))
    assert {str(p.relative_to(folder)) for p in files} >= finished
    saved = {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in files}
    for p in files:
        assert Gait.load(p).success

    second = gaitopt(*ARGS, "-o", str(folder))
    log, _ = second.communicate(timeout=300)
    assert second.returncode == 0, log
    assert f"{len(files)} kept from an earlier run" in log
    assert sum(line.startswith("ok ") for line in log.splitlines()) == 5 - len(files)
    for p, (data, mtime) in saved.items():  # nothing finished was recomputed
        assert p.read_bytes() == data and p.stat().st_mtime_ns == mtime
    rows = read_summary(folder / SUMMARY_FILE)
    assert len(rows) == 5 and all(r.success for r in rows)
    for r in rows:
        assert Gait.load(folder / r.file).cost_value == r.cost
    assert not list(folder.rglob("*.tmp"))
