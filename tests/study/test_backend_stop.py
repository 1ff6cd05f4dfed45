"""Closing a local backend without waiting (Ctrl-C) ends its running points: the command
exits at once instead of when each running solve ends; SIGTERM does the same."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from gaitopt.study.executors import process_exists

SRC = Path(__file__).resolve().parents[2] / "src"

SCRIPT = textwrap.dedent("""
    import sys, time
    sys.path.insert(0, {src!r})
    from gaitopt.study.executors import local_backend

    if __name__ == "__main__":
        backend = local_backend(1)
        future = backend.submit(time.sleep, 120.0)  # a point that runs for two minutes
        deadline = time.monotonic() + 60.0
        while not future.running() and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)
        backend.close(wait=False)
        print("closed", flush=True)
""")


def test_close_without_waiting_ends_the_running_points(tmp_path: Path) -> None:
    script = tmp_path / "stop.py"
    script.write_text(SCRIPT.format(src=str(SRC)), encoding="utf-8")
    start = time.monotonic()
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=100)
    elapsed = time.monotonic() - start
    assert done.returncode == 0, done.stderr
    assert "closed" in done.stdout
    assert elapsed < 60.0, f"the process waited {elapsed:.0f} s for its running point"


def descendants(pid: int) -> set[int]:
    """The processes below ``pid`` (children, grandchildren, ...), from /proc."""
    parents: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        parents[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    found: set[int] = set()
    frontier = {pid}
    while frontier:
        frontier = {p for p, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def alive(pid: int) -> bool:
    try:
        state = (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def stop_a_solving_sweep(out: Path, signum: int) -> tuple[int, str, set[int], list[int]]:
    """Start ``gaitopt sweep`` (one worker), send ``signum`` to it once its worker process
    runs, and return its exit status, its output, the processes below it just before the
    signal, and those of them still running 20 s after it exited. None outlives the call."""
    command = [sys.executable, "-c", "import sys; from gaitopt.cli import main; "
               "sys.exit(main(sys.argv[1:]))", "sweep", "-o", str(out), "--speeds",
               "3:60:3", "--variants", "all", "--workers", "1"]
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, env=env)
    below: set[int] = set()
    try:
        deadline = time.monotonic() + 120.0  # a worker process (the pool's, below its server)
        while len(descendants(process.pid)) < 2 and time.monotonic() < deadline:
            assert process.poll() is None, process.stdout.read() if process.stdout else ""
            time.sleep(0.2)
        time.sleep(2.0)
        below = descendants(process.pid)
        assert len(below) >= 2, "no worker process started"
        process.send_signal(signum)
        status = process.wait(timeout=60)
        deadline = time.monotonic() + 20.0
        while any(alive(p) for p in below) and time.monotonic() < deadline:
            time.sleep(0.2)
        running = sorted(p for p in below if alive(p))
    finally:
        if process.poll() is None:
            process.kill()
        for pid in descendants(process.pid) | below:
            if alive(pid):  # no orphan of a failed check outlives the test
                os.kill(pid, signal.SIGKILL)
    output = process.stdout.read() if process.stdout else ""
    return status, output, below, running


ON_LINUX = pytest.mark.skipif(not Path("/proc/self/stat").exists(),
                              reason="reads the process tree from /proc")


@ON_LINUX
def test_sigterm_stops_a_sweep_and_its_workers_like_ctrl_c(tmp_path: Path) -> None:
    """``kill PID`` (SIGTERM) of a ``gaitopt sweep`` while its worker solves: the command
    ends its worker processes and exits with 143 at once, saying how to resume, and leaves
    no half-written file. Before, the main process died alone and its workers went on
    without a parent (see the next test)."""
    status, output, below, running = stop_a_solving_sweep(tmp_path / "sweep", signal.SIGTERM)
    assert status == 143, output
    assert "interrupted" in output and "rerun the same command to resume" in output, output
    assert not running, f"still running 20 s after the sweep: {running} of {sorted(below)}"
    assert not list((tmp_path / "sweep").rglob("*.tmp"))


@ON_LINUX
def test_the_workers_end_when_the_sweep_is_killed(tmp_path: Path) -> None:
    """SIGKILL cannot be handled: the workers notice that the driver is gone
    (``gaitopt.study.executors.end_with_driver``) and end. Before, the worker and its
    forkserver finished the point for nobody and then waited for work forever."""
    status, _, below, running = stop_a_solving_sweep(tmp_path / "sweep", signal.SIGKILL)
    assert status == -signal.SIGKILL
    assert not running, f"still running 20 s after the sweep: {running} of {sorted(below)}"


def test_process_exists_tells_a_running_process_from_an_ended_one() -> None:
    assert process_exists(os.getpid())
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()  # ended and reaped: its PID names no process
    assert not process_exists(child.pid)
