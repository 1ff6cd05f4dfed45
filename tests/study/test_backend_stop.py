"""Closing a local backend without waiting (Ctrl-C) ends its running points: the command
exits at once instead of when each running solve ends."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import time
from pathlib import Path

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
