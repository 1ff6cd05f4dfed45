"""The general problem's speed targets (issue 27, item 3), each against a reference measured in
the same run, every solve a whole ``gaitopt solve`` process:

1. **cold seven-link against cold five-link**: ``gaitopt solve --model seven-link --speed
   60m/min`` (the heel-toe walk in full coordinates, the model's defaults) against ``gaitopt
   solve --speed 60m/min`` (the five-link walk); target: at most 3 times as long;
2. **warm start of the seven-link from a gait file**: ``gaitopt solve --model seven-link
   --speed 63m/min --warm-start seven.gait.json`` (the cold solve's file, +5 % speed), with
   ``--knots`` set to the file's grid (one grid, as a sweep's chain solves) and with the knots
   left to the model (then the check grid is solved for the estimate); the solve's own time
   (the gait file's ``solver.wall_time_s``: the stages, without the process start and the
   imports) against the target of 0.3 s; the five-link's the same way beside it;
3. **automatic refinement on a solve that is already converged**: the warm start at the
   file's own speed (60 m/min) with the knots left to the model (refinement on: the estimate
   must come from a check grid, and a grid outside the accuracy is refined) against the same
   with ``--knots`` set to the file's grid (refinement off, one grid, no estimate); target:
   at most +50 % of solve time.

Each process: wall time, CPU time (user + system, from ``os.wait4``), peak resident set size,
the cost and the stages. Byte code is written (by one unmeasured process first) and reused
in a folder of the temporary directory, as an installed package keeps its ``.pyc`` files
(``--no-bytecode``: compiled in every process where ``PYTHONDONTWRITEBYTECODE`` is set).
The function cache on disk (``gaitopt.gait.solve.function_cache``) is whatever the machine
holds; ``--warmup`` runs each cold solve once first, unmeasured.

    PYTHONPATH=src python bench/general.py [--repeat 1] [--warmup] [--only cold|warm|refine]
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
TARGETS = {"cold": 3.0, "warm": 0.3, "refine": 0.5}


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def child_env(bytecode: Path | None) -> dict[str, str]:
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    if bytecode is not None:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(bytecode)
    return env


def solve(args: list[str], out: Path, env: dict[str, str]) -> dict[str, Any]:
    """One ``gaitopt solve ARGS -o OUT`` process: wall, CPU (s), peak RSS (MB), and from the
    gait file the cost, the solve's wall time and the stages."""
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "gaitopt", "solve", *args, "-o", str(out)],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    err = proc.stderr.read().decode() if proc.stderr else ""
    code = os.waitstatus_to_exitcode(status)
    row: dict[str, Any] = {"args": " ".join(args), "wall_s": wall,
                           "cpu_s": usage.ru_utime + usage.ru_stime,
                           "peak_rss_mb": usage.ru_maxrss / 1024, "exit": code}
    if code not in (0, 3) or not out.exists():
        row.update(ok=False, error=err[-2000:])
        return row
    gait = json.loads(out.read_text())
    solver = gait["solver"]
    row.update(ok=bool(solver["success"]), cost=gait["cost"]["value"],
               solve_s=solver["wall_time_s"],
               stages=[(s["name"], "+".join(str(k) for k in s["knots"]), s["iterations"])
                       for s in solver["stages"]],
               knots=solver["accuracy"]["knots"],
               within=solver["accuracy"].get("within_target"))
    return row


def show(name: str, row: dict[str, Any]) -> None:
    if not row.get("ok"):
        print(f"  {name}: FAILED (exit {row['exit']}) {row.get('error', '')}", flush=True)
        return
    stages = ", ".join(f"{n} {k} {i} it" for n, k, i in row["stages"])
    print(f"  {name}: process {row['wall_s']:.2f} s ({row['cpu_s']:.2f} CPU), solve "
          f"{row['solve_s']:.2f} s, peak RSS {row['peak_rss_mb']:.0f} MB, J {row['cost']:.6g}; "
          f"{stages}; load {load()}", flush=True)


def knots_arg(knots: dict[str, int]) -> str:
    return ",".join(f"{k}={v}" for k, v in knots.items())


def median(rows: list[dict[str, Any]], key: str) -> float:
    return statistics.median(r[key] for r in rows if r.get("ok"))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--warmup", action="store_true",
                    help="run each cold solve once first, unmeasured")
    ap.add_argument("--only", choices=["cold", "warm", "refine"], action="append")
    ap.add_argument("--no-bytecode", action="store_true")
    ap.add_argument("--keep", type=Path, help="keep the gait files in this folder")
    args = ap.parse_args(argv)
    only = set(args.only or ["cold", "warm", "refine"])
    print(f"load average before: {load()} ({os.cpu_count()} cores)")
    with tempfile.TemporaryDirectory(prefix="gaitopt-general-") as tmp_name:
        tmp = args.keep or Path(tmp_name)
        tmp.mkdir(parents=True, exist_ok=True)
        env = child_env(None if args.no_bytecode
                        else Path(tempfile.gettempdir()) / "gaitopt-bench-pyc")
        if not args.no_bytecode:  # byte code written once, unmeasured
            subprocess.run([sys.executable, "-c", "import gaitopt.cli, gaitopt.gait.api"],
                           env=env, check=True)
        models = {"five-link": ["--speed", "60m/min"],
                  "seven-link": ["--model", "seven-link", "--speed", "60m/min"]}
        files = {m: tmp / f"{m}-60.gait.json" for m in models}
        results: dict[str, dict[str, list[dict[str, Any]]]] = {}

        def record(kind: str, model: str, row: dict[str, Any]) -> None:
            results.setdefault(kind, {}).setdefault(model, []).append(row)
            show(f"{kind:7s} {model}", row)

        for model, cli in models.items():  # the files the warm starts need, or a warm-up
            if args.warmup or ("cold" not in only and not files[model].exists()):
                show(f"warm-up {model}", solve(cli, files[model], env))
        if "cold" in only:
            for i in range(args.repeat):
                order = list(models) if i % 2 == 0 else list(reversed(models))
                for model in order:
                    record("cold", model, solve(models[model], files[model], env))
        if "warm" in only:
            for _ in range(args.repeat):
                for model, cli in models.items():
                    faster = [a if a != "60m/min" else "63m/min" for a in cli]
                    start = [*faster, "--warm-start", str(files[model])]
                    grid = json.loads(files[model].read_text())["solver"]["accuracy"]["knots"]
                    record("warm", model, solve(start, tmp / f"{model}-63.gait.json", env))
                    record("warm-knots", model, solve([*start, "--knots", knots_arg(grid)],
                                                      tmp / f"{model}-63k.gait.json", env))
        if "refine" in only:
            for _ in range(args.repeat):
                for model, cli in models.items():
                    grid = json.loads(files[model].read_text())["solver"]["accuracy"]["knots"]
                    record("refine", model, solve([*cli, "--warm-start", str(files[model])],
                                                  tmp / f"{model}-again.gait.json", env))
                    record("fixed", model, solve([*cli, "--warm-start", str(files[model]),
                                                  "--knots", knots_arg(grid)],
                                                 tmp / f"{model}-fixed.gait.json", env))
    print(f"\n| figure (median of {args.repeat}) | value | reference | ratio | target | met | "
          "peak RSS MB |")
    print("| --- | ---: | ---: | ---: | ---: | :---: | ---: |")
    if "cold" in results and all(m in results["cold"] for m in models):
        for key, unit in (("wall_s", "wall"), ("cpu_s", "CPU")):
            seven, five = median(results["cold"]["seven-link"], key), \
                median(results["cold"]["five-link"], key)
            print(f"| cold seven-link / five-link process, {unit} s | {seven:.2f} | {five:.2f} | "
                  f"{seven / five:.2f} | {TARGETS['cold']:g} | "
                  f"{'yes' if seven / five <= TARGETS['cold'] else 'no'} | "
                  f"{median(results['cold']['seven-link'], 'peak_rss_mb'):.0f}, "
                  f"{median(results['cold']['five-link'], 'peak_rss_mb'):.0f} |")
    for kind, label in (("warm-knots", "the file's knots given (one grid)"),
                        ("warm", "knots left to the model (refines: check grid)")):
        if kind not in results:
            continue
        seven = median(results[kind]["seven-link"], "solve_s")
        five = median(results[kind]["five-link"], "solve_s")
        print(f"| warm start of the seven-link from its gait file (+5 % speed), {label}, "
              f"solve s | {seven:.3f} | {five:.3f} (five-link) | {seven / five:.2f} | "
              f"{TARGETS['warm']:g} s | {'yes' if seven <= TARGETS['warm'] else 'no'} | "
              f"{median(results[kind]['seven-link'], 'peak_rss_mb'):.0f} |")
    if "refine" in results:
        for model in models:
            on = median(results["refine"][model], "solve_s")
            off = median(results["fixed"][model], "solve_s")
            extra = on / off - 1
            print(f"| automatic refinement on a converged {model} solve, solve s | {on:.3f} | "
                  f"{off:.3f} (knots given) | {extra:+.0%} | +{TARGETS['refine']:.0%} | "
                  f"{'yes' if extra <= TARGETS['refine'] else 'no'} | "
                  f"{median(results['refine'][model], 'peak_rss_mb'):.0f} |")
    print(f"load average after: {load()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
