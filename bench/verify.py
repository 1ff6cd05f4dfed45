"""What ``verify`` costs a user: ``gaitopt verify FILE`` and ``gaitopt solve`` as whole processes
(``gaitopt solve`` verifies its answer before it writes it), and ``verify_gait`` in one process
(the first call, which builds the multibody functions, and a later one), for the five-link
walk and the seven-link heel-toe walk at 60 m/min.

The gait files are solved once first (unmeasured, by this side's code). The ``gaitopt solve``
row of the seven-link is its warm start at 63 m/min from its 60 m/min file on the file's knots
(``bench/general.py``'s ``warm-knots`` case), of the five-link its cold solve at 60 m/min.
Each process: wall time, CPU time (user + system, ``os.wait4``), peak resident set size.
Byte code is written once per side first (as an installed package keeps its ``.pyc`` files);
the disk cache (``GAITOPT_CACHE``) is whatever the machine holds, and one unmeasured round
fills it for both sides.

With ``--reference SRC`` (a source folder, e.g. a worktree of the previous main's ``src``)
every row is measured for both sides, alternately, and the table prints their ratio.

    PYTHONPATH=src python bench/verify.py [--repeat 3] [--reference /path/to/main/src]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent

#: The child of the in-process rows: prints one JSON line (times in s).
IN_PROCESS = """
import json, sys, time
from gaitopt import Gait, verify_gait
gait = Gait.load(sys.argv[1])
t0 = time.perf_counter()
first = verify_gait(gait)
t1 = time.perf_counter()
again = verify_gait(gait)
t2 = time.perf_counter()
print(json.dumps(dict(first=t1 - t0, again=t2 - t1, passed=first.passed and again.passed,
                      values=[c.value for c in again.checks])))
"""


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def child_env(src: Path, pyc: Path) -> dict[str, str]:
    env = dict(os.environ, PYTHONPATH=str(src), OPENBLAS_NUM_THREADS="1",
               PYTHONPYCACHEPREFIX=str(pyc))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def timed(cmd: list[str], env: dict[str, str]) -> dict[str, Any]:
    """One process with ``os.wait4``: wall, CPU (s), peak RSS (MB), exit status, stdout."""
    start = time.perf_counter()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(cmd, env=env, stdout=out, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        out.seek(0)
        err.seek(0)
        lines = out.read().decode().strip().splitlines()
        error = err.read().decode()[-1500:]
    return {"wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime,
            "peak_rss_mb": usage.ru_maxrss / 1024, "exit": os.waitstatus_to_exitcode(status),
            "last": lines[-1] if lines else "", "error": error}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--reference", type=Path,
                    help="a source folder measured beside this one (the 'before' column)")
    args = ap.parse_args(argv)
    print(f"load average before: {load()} ({os.cpu_count()} cores)")
    sides = {"this": REPO / "src"}
    if args.reference is not None:
        sides["before"] = args.reference.resolve()
    gaitopt = [sys.executable, "-m", "gaitopt"]
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-verify-") as tmp_name:
        tmp = Path(tmp_name)
        pyc = Path(tempfile.gettempdir()) / "gaitopt-bench-pyc"
        envs = {side: child_env(src, pyc / side) for side, src in sides.items()}
        models = {"five-link": ["--speed", "60m/min"],
                  "seven-link": ["--model", "seven-link", "--speed", "60m/min"]}
        files = {m: tmp / f"{m}-60.gait.json" for m in models}
        for model, cli in models.items():  # the files, by this side's code, unmeasured
            done = timed([*gaitopt, "solve", *cli, "-o", str(files[model])], envs["this"])
            if done["exit"] != 0:
                print(f"  solving {model} failed: {done['error']}")
                return 1

        def cases(model: str) -> dict[str, list[str]]:
            file = files[model]
            if model == "seven-link":
                knots = json.loads(file.read_text())["solver"]["accuracy"]["knots"]
                solve = [*gaitopt, "solve", "--model", "seven-link", "--speed", "63m/min",
                         "--warm-start", str(file), "--knots",
                         ",".join(f"{k}={v}" for k, v in knots.items()),
                         "-o", str(tmp / "out.gait.json")]
            else:
                solve = [*gaitopt, "solve", *models[model], "-o", str(tmp / "out.gait.json")]
            return {"gaitopt verify": [*gaitopt, "verify", str(file)],
                    "gaitopt solve": solve,
                    "verify_gait": [sys.executable, "-c", IN_PROCESS, str(file)]}

        rows: dict[tuple[str, str, str], list[dict[str, Any]]] = {}
        for i in range(args.repeat + 1):  # round 0 fills the caches, unmeasured
            for model in models:
                for case, cmd in cases(model).items():
                    for side in (list(sides) if i % 2 else list(reversed(sides))):
                        row = timed(cmd, envs[side])
                        if row["exit"] != 0 and case != "gaitopt verify":
                            print(f"  {side} {model} {case}: FAILED {row['error']}")
                            return 1
                        if case == "verify_gait":
                            row.update(json.loads(row["last"]))
                        if i == 0:
                            continue
                        rows.setdefault((model, case, side), []).append(row)
                        extra = (f", first call {row['first']:.3f} s, again {row['again']:.3f} s"
                                 if case == "verify_gait" else "")
                        print(f"  {side:6s} {model:10s} {case:15s} process {row['wall_s']:.2f} s "
                              f"({row['cpu_s']:.2f} CPU), {row['peak_rss_mb']:.0f} MB, exit "
                              f"{row['exit']}{extra}; load {load()}", flush=True)
        print()
        head = f"| model | what | figure (median of {args.repeat}) | this |"
        if "before" in sides:
            head += " before | ratio |"
        print(head)
        print("| --- | --- | --- | ---: |" + (" ---: | ---: |" if "before" in sides else ""))
        for model in models:
            for case in cases(model):
                keys = ["wall_s", "cpu_s"] + (["first", "again"] if case == "verify_gait" else [])
                for key in keys:
                    this = statistics.median(r[key] for r in rows[model, case, "this"])
                    line = f"| {model} | {case} | {key} | {this:.3f} |"
                    if "before" in sides:
                        before = statistics.median(r[key] for r in rows[model, case, "before"])
                        line += f" {before:.3f} | {this / before:.2f} |"
                    print(line)
        if "before" in sides:  # the checks' values: the same answer from both sides
            for model in models:
                a = rows[model, "verify_gait", "this"][-1]["values"]
                b = rows[model, "verify_gait", "before"][-1]["values"]
                worst = max((abs(x - y) / max(abs(y), 1e-300) for x, y in zip(a, b, strict=True)
                             if x != y), default=0.0)
                print(f"{model}: the checks' values, largest relative difference {worst:.3g}")
    print(f"load average after: {load()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
