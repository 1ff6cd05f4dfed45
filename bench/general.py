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
The function cache on disk (``gaitopt.dynamics.function_cache``) is whatever the machine
holds; ``--warmup`` runs each cold solve once first, unmeasured.

4. **the warm start through the Python API, broken down** (``--only api``): one process per
   model that imports gaitopt, loads the 60 m/min gait file and calls ``solve_gait`` at 63 m/min
   with it as ``warm_start`` (the knots left to the model): the imports, the whole call (CPU
   and wall), each stage's iterations and seconds, and the rest of the call (building the
   transcriptions from the function cache, the record).

With ``--reference SRC`` (a source folder, e.g. a worktree of the previous main's ``src``)
every row is measured for both sources, alternately, each side warm-starting from its own
cold solve's file: the table then has a "before" column beside each figure.

    PYTHONPATH=src python bench/general.py [--repeat 1] [--warmup] [--only cold|warm|refine|api]
        [--reference /path/to/main/src]
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


def child_env(bytecode: Path | None, src: Path = REPO / "src") -> dict[str, str]:
    env = dict(os.environ, PYTHONPATH=str(src), OPENBLAS_NUM_THREADS="1")
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


#: The child of the API rows: prints one JSON line (times in s).
API_CHILD = """
import json, os, sys, time
c0, t0 = time.process_time(), time.perf_counter()
from gaitopt import Gait, GaitOptions, solve_gait
c1, t1 = time.process_time(), time.perf_counter()
gait = Gait.load(sys.argv[2])
out = solve_gait(sys.argv[1], GaitOptions(speed=float(sys.argv[3])), warm_start=gait)
c2, t2 = time.process_time(), time.perf_counter()
stages = [(s["name"], "+".join(str(k) for k in s["knots"]), s["iterations"], s["wall_time_s"])
          for s in out.solver["stages"]]
print(json.dumps(dict(ok=bool(out.success), import_cpu=c1 - c0, import_wall=t1 - t0,
                      call_cpu=c2 - c1, call_wall=t2 - t1, solve_wall=out.solver["wall_time_s"],
                      stages=stages, cost=out.cost_value,
                      check_cost=out.solver["accuracy"].get("check_cost"),
                      cost_error=out.solver["accuracy"].get("cost_error"))))
"""


def api_warm(model: str, file: Path, speed: float, env: dict[str, str]) -> dict[str, Any]:
    """One process: ``solve_gait(model, GaitOptions(speed=speed), warm_start=Gait.load(file))``
    (:data:`API_CHILD`), with its peak RSS and CPU from ``os.wait4``."""
    proc = subprocess.Popen([sys.executable, "-c", API_CHILD, model, str(file), str(speed)],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    out = proc.stdout.read().decode() if proc.stdout else ""
    err = proc.stderr.read().decode() if proc.stderr else ""
    try:
        row: dict[str, Any] = json.loads(out.strip().splitlines()[-1])
    except (IndexError, ValueError):
        return {"ok": False, "exit": os.waitstatus_to_exitcode(status), "error": err[-2000:]}
    stage_s = sum(s[3] for s in row["stages"])
    row.update(cpu_s=usage.ru_utime + usage.ru_stime, peak_rss_mb=usage.ru_maxrss / 1024,
               exit=0, solve_s=row["call_wall"], rest_wall=row["call_wall"] - stage_s)
    return row


def show_api(name: str, row: dict[str, Any]) -> None:
    if not row.get("ok"):
        print(f"  {name}: FAILED {row.get('error', '')}", flush=True)
        return
    stages = ", ".join(f"{n} {k} {i} it {t:.2f} s" for n, k, i, t in row["stages"])
    print(f"  {name}: imports {row['import_wall']:.2f} s ({row['import_cpu']:.2f} CPU); "
          f"solve_gait {row['call_wall']:.2f} s ({row['call_cpu']:.2f} CPU): {stages}; "
          f"the rest (builds, record) {row['rest_wall']:.2f} s; process CPU "
          f"{row['cpu_s']:.2f} s, peak RSS {row['peak_rss_mb']:.0f} MB, J {row['cost']:.9g}, "
          f"check J {row['check_cost']}; load {load()}", flush=True)


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
    ap.add_argument("--only", choices=["cold", "warm", "refine", "api"], action="append")
    ap.add_argument("--no-bytecode", action="store_true")
    ap.add_argument("--keep", type=Path, help="keep the gait files in this folder")
    ap.add_argument("--reference", type=Path,
                    help="a source folder measured beside this one (the 'before' column)")
    args = ap.parse_args(argv)
    only = set(args.only or ["cold", "warm", "refine", "api"])
    print(f"load average before: {load()} ({os.cpu_count()} cores)")
    sides = {"this": REPO / "src"}
    if args.reference is not None:
        sides["before"] = args.reference.resolve()
    with tempfile.TemporaryDirectory(prefix="gaitopt-general-") as tmp_name:
        tmp = args.keep or Path(tmp_name)
        tmp.mkdir(parents=True, exist_ok=True)
        pyc = Path(tempfile.gettempdir()) / "gaitopt-bench-pyc"
        envs = {side: child_env(None if args.no_bytecode else pyc / side, src)
                for side, src in sides.items()}
        if not args.no_bytecode:  # byte code written once, unmeasured
            for env in envs.values():
                subprocess.run([sys.executable, "-c", "import gaitopt.cli, gaitopt.gait.api"],
                               env=env, check=True)
        models = {"five-link": ["--speed", "60m/min"],
                  "seven-link": ["--model", "seven-link", "--speed", "60m/min"]}
        files = {(side, m): tmp / f"{side}-{m}-60.gait.json" for side in sides for m in models}
        results: dict[tuple[str, str], dict[str, list[dict[str, Any]]]] = {}

        def record(side: str, kind: str, model: str, row: dict[str, Any]) -> None:
            results.setdefault((side, kind), {}).setdefault(model, []).append(row)
            (show_api if kind == "api" else show)(f"{side:6s} {kind:10s} {model}", row)

        def each_side(i: int) -> list[str]:
            return list(sides) if i % 2 == 0 else list(reversed(sides))

        for side, env in envs.items():  # the files the warm starts need, or a warm-up
            for model, cli in models.items():
                if args.warmup or ("cold" not in only and not files[side, model].exists()):
                    show(f"{side} warm-up {model}", solve(cli, files[side, model], env))
        if "cold" in only:
            for i in range(args.repeat):
                order = list(models) if i % 2 == 0 else list(reversed(models))
                for model in order:
                    for side in each_side(i):
                        record(side, "cold", model,
                               solve(models[model], files[side, model], envs[side]))
        if "warm" in only:
            for i in range(args.repeat):
                for model, cli in models.items():
                    for side in each_side(i):
                        file, env = files[side, model], envs[side]
                        faster = [a if a != "60m/min" else "63m/min" for a in cli]
                        start = [*faster, "--warm-start", str(file)]
                        grid = json.loads(file.read_text())["solver"]["accuracy"]["knots"]
                        record(side, "warm", model,
                               solve(start, tmp / f"{side}-{model}-63.gait.json", env))
                        record(side, "warm-knots", model,
                               solve([*start, "--knots", knots_arg(grid)],
                                     tmp / f"{side}-{model}-63k.gait.json", env))
        if "refine" in only:
            for i in range(args.repeat):
                for model, cli in models.items():
                    for side in each_side(i):
                        file, env = files[side, model], envs[side]
                        grid = json.loads(file.read_text())["solver"]["accuracy"]["knots"]
                        record(side, "refine", model,
                               solve([*cli, "--warm-start", str(file)],
                                     tmp / f"{side}-{model}-again.gait.json", env))
                        record(side, "fixed", model,
                               solve([*cli, "--warm-start", str(file), "--knots",
                                      knots_arg(grid)],
                                     tmp / f"{side}-{model}-fixed.gait.json", env))
        if "api" in only:
            for i in range(args.repeat):
                for model in models:
                    for side in each_side(i):
                        record(side, "api", model,
                               api_warm(model, files[side, model], 1.05, envs[side]))
    table(results, sides, models, args.repeat)
    print(f"load average after: {load()}")
    return 0


def table(results: dict[tuple[str, str], dict[str, list[dict[str, Any]]]],
          sides: dict[str, Path], models: dict[str, list[str]], repeat: int) -> None:
    """The targets' table: one row per figure, this side's value, its reference (the
    five-link, or the solve without refinement), ratio, target and whether met; with a
    reference source the same figures of the "before" side beside them."""
    before = "before" in sides
    print(f"\n| figure (median of {repeat}) | value | reference | ratio | target | met | "
          + ("before: value | reference | ratio | " if before else "") + "peak RSS MB |")
    print("| --- | ---: | ---: | ---: | ---: | :---: | " + ("---: | ---: | ---: | " if before
                                                           else "") + "---: |")

    def have(side: str, kind: str, model: str) -> bool:
        return any(r.get("ok") for r in results.get((side, kind), {}).get(model, []))

    def cells(side: str, kinds: tuple[str, str], mods: tuple[str, str], key: str
              ) -> tuple[float, float] | None:
        if not (have(side, kinds[0], mods[0]) and have(side, kinds[1], mods[1])):
            return None
        return (median(results[side, kinds[0]][mods[0]], key),
                median(results[side, kinds[1]][mods[1]], key))

    def line(label: str, kinds: tuple[str, str], mods: tuple[str, str], key: str,
             fmt: str, ratio: str, target: str, met: Any) -> None:
        now = cells("this", kinds, mods, key)
        if now is None:
            return
        value, ref = now

        def rat(v: float, r: float) -> str:
            return f"{v / r:.2f}" if ratio == "x" else f"{v / r - 1:+.0%}"

        row = (f"| {label} | {value:{fmt}} | {ref:{fmt}} | {rat(value, ref)} | {target} | "
               f"{'yes' if met(value, ref) else 'no'} | ")
        if before:
            old = cells("before", kinds, mods, key)
            row += ("| | | " if old is None else
                    f"{old[0]:{fmt}} | {old[1]:{fmt}} | {rat(*old)} | ")
        rss = median(results["this", kinds[0]][mods[0]], "peak_rss_mb")
        print(row + f"{rss:.0f} |")

    for key, unit in (("wall_s", "wall"), ("cpu_s", "CPU")):
        line(f"cold seven-link / five-link process, {unit} s", ("cold", "cold"),
             ("seven-link", "five-link"), key, ".2f", "x", f"{TARGETS['cold']:g}x",
             lambda v, r: v / r <= TARGETS["cold"])
    for kind, label, key, unit in (
            ("warm-knots", "the file's knots given (one grid)", "solve_s", "solve wall"),
            ("warm-knots", "the file's knots given (one grid)", "cpu_s", "process CPU"),
            ("warm", "knots left to the model (refines: check grid)", "solve_s", "solve wall"),
            ("warm", "knots left to the model (refines: check grid)", "cpu_s", "process CPU"),
            ("api", "solve_gait, knots left to the model", "call_wall", "call wall"),
            ("api", "solve_gait, knots left to the model", "call_cpu", "call CPU")):
        line(f"warm start of the seven-link from its gait file (+5 % speed), {label}, {unit} "
             "s (reference: five-link)", (kind, kind), ("seven-link", "five-link"), key,
             ".3f", "x", f"{TARGETS['warm']:g} s", lambda v, r: v <= TARGETS["warm"])
    for model in models:
        line(f"automatic refinement on a converged {model} solve, solve s (reference: knots "
             "given)", ("refine", "fixed"), (model, model), "solve_s", ".3f", "%",
             f"+{TARGETS['refine']:.0%}", lambda v, r: v / r - 1 <= TARGETS["refine"])


if __name__ == "__main__":
    sys.exit(main())
