"""The feet studies' times (issue 27, item 3), each a whole ``gaitopt study`` process into an
empty folder, against its target and against the five-link study of the same kind measured in
the same run:

1. **the feet cost study**: ``gaitopt study --costs --model seven-link`` (7 cases, the
   accuracy pass on) against ``gaitopt study --costs`` (the five-link biped); target: at most
   10 minutes;
2. **the paper's study with feet** (``--only paper``, or ``--only all``): ``gaitopt study
   --model seven-link`` against ``gaitopt study`` (the five-link study of ``make run``);
   target: at most 3 minutes.

Each process: wall time, CPU time of the process and its workers (user + system) and the
peak of their summed resident set sizes, both sampled with psutil (installed with
dask.distributed), the exit status,
and the lines of the study's own tally that say what converged (``accuracy: ...``, ``done
in ...``). The function cache on disk (``gaitopt.dynamics.function_cache``) is whatever the
machine holds (``GAITOPT_CACHE`` chooses it); the load average is printed before and after.

    PYTHONPATH=src python bench/studies.py [--only costs|paper|all] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import psutil

REPO = Path(__file__).resolve().parent.parent
#: The targets (s) of issue 27.
TARGETS = {"costs": 600.0, "paper": 180.0}
#: The commands (after ``gaitopt``) of each study: the feet one and its five-link reference.
STUDIES = {
    "costs": (["study", "--costs", "--model", "seven-link"], ["study", "--costs"]),
    "paper": (["study", "--model", "seven-link"], ["study"]),
}
#: How often the process tree is sampled (s).
SAMPLE_S = 0.5
#: The lines of a study's output kept in the table's notes.
TALLY = ("accuracy:", "cost study done", "study done", "done in", "no optimal speed")


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def study(args: list[str], out: Path, workers: int) -> dict[str, Any]:
    """One ``gaitopt ARGS -o OUT --workers N`` process: wall (s), CPU of it and every process
    under it (s), the peak of their summed resident set sizes (MB), exit status and the
    tally lines of its output. The workers run under a forkserver that ``os.wait4`` does not
    see, so the process tree is sampled every :data:`SAMPLE_S` with psutil (a worker's last
    fraction of a sample is missed)."""
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), OPENBLAS_NUM_THREADS="1")
    with tempfile.TemporaryFile(mode="w+") as log:
        start = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-m", "gaitopt", *args, "-o", str(out),
                                 "--workers", str(workers)], env=env, stdout=log,
                                stderr=subprocess.STDOUT, text=True)
        top = psutil.Process(proc.pid)
        cpu: dict[int, float] = {}
        peak = 0.0
        while proc.poll() is None:
            rss = 0.0
            for p in [top, *top.children(recursive=True)]:
                try:
                    times = p.cpu_times()
                    cpu[p.pid] = times.user + times.system
                    rss += p.memory_info().rss
                except psutil.Error:  # ended between the listing and the reading
                    continue
            peak = max(peak, rss)
            time.sleep(SAMPLE_S)
        wall = time.perf_counter() - start
        log.seek(0)
        output = log.read()
    lines = [line.strip() for line in output.splitlines()
             if line.strip().startswith(TALLY)]
    return {"args": " ".join(args), "wall_s": wall, "exit": proc.returncode,
            "cpu_s": sum(cpu.values()), "peak_rss_mb": peak / 2**20, "tally": lines}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", choices=["costs", "paper", "all"], default="costs")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    kinds = ["costs", "paper"] if args.only == "all" else [args.only]
    print(f"load average before: {load()} ({os.cpu_count()} cores)", flush=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-studies-") as tmp:
        for kind in kinds:
            feet_args, five_args = STUDIES[kind]
            five = study(five_args, Path(tmp) / f"{kind}-five", args.workers)
            print(f"  {kind} five-link: {five['wall_s']:.0f} s, exit {five['exit']}; "
                  + " | ".join(five["tally"]) + f"; load {load()}", flush=True)
            feet = study(feet_args, Path(tmp) / f"{kind}-feet", args.workers)
            print(f"  {kind} seven-link: {feet['wall_s']:.0f} s, exit {feet['exit']}; "
                  + " | ".join(feet["tally"]) + f"; load {load()}", flush=True)
            rows.append((kind, feet, five))
    print("\n| study | seven-link wall s | CPU s | five-link wall s | ratio | target | met | "
          "peak RSS MB, all processes (seven-link) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | :---: | ---: |")
    for kind, feet, five in rows:
        met = "yes" if feet["exit"] == 0 and feet["wall_s"] <= TARGETS[kind] else "no"
        print(f"| {' '.join(STUDIES[kind][0])} | {feet['wall_s']:.0f} | {feet['cpu_s']:.0f} | "
              f"{five['wall_s']:.0f} | "
              f"{feet['wall_s'] / five['wall_s']:.1f} | {TARGETS[kind]:.0f} | {met} | "
              f"{feet['peak_rss_mb']:.0f} |")
    print(f"load average after: {load()}")


if __name__ == "__main__":
    main()
