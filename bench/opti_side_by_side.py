"""gaitopt beside a plain CasADi ``Opti`` script on the same published gait problem.

The problem: Kelly's five-link biped step (single support only, an impact, periodic, step
length 0.5 m and step time 0.7 s fixed, torque squared per metre) on gaitopt's five-link model,
40 uniform knots, separated Hermite-Simpson, exact Hessian, IPOPT with MUMPS. The plain script
is ``bench/opti_five_link.py`` (written directly with CasADi, no gaitopt import; its docstring
states the problem). gaitopt solves the same problem through its public API::

    solve_gait("five-link", GaitOptions(speed=L / T, step_length=L, single_support_fraction=1,
                                        knots={"single_support": 40}, knot_spacing="uniform"))

which runs its staged solve from its own naive guess (coarse stages, the 40-knot target grid,
then the 60-knot check grid for its error estimate, which the plain script does not give).
The measured processes reuse byte code, as an installed package keeps its ``.pyc`` files:
``PYTHONPYCACHEPREFIX`` in a folder of the temporary directory, written by one unmeasured
process of each kind first (where ``PYTHONDONTWRITEBYTECODE`` is set, as on the project
machine, the bench starts itself again without it: a spawned worker inherits the flag as
``-B``, and with a prefix folder it would then compile every module it imports, numpy's and
CasADi's too, in every process). ``--no-bytecode`` leaves the environment as it is.

Both run in fresh worker processes of one process pool (``spawn``, one task per process, one
worker at a time, the two alternating), ``--repeat`` times each. Per run: the whole process
(from the worker process's creation, read from ``/proc/self/stat``, to the result: interpreter
start, imports, model, build, solve), the solve (build and IPOPT: everything after the
imports), both as wall and CPU seconds, and the peak resident set size. The costs must agree
within ``--agree`` (relative, default 1e-4) before any time is printed. Printed: each run,
the median of each figure, and the ratios gaitopt / Opti (target 0.3, goal 0.25).

    PYTHONPATH=src python bench/opti_side_by_side.py [--repeat 3] [--opti-args=--expand]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
STEP_LENGTH, STEP_TIME, KNOTS = 0.5, 0.7, 40
TARGET, GOAL = 0.3, 0.25


def process_age_s() -> float:
    """Seconds since this process was created (Linux ``/proc``, 10 ms resolution)."""
    with open("/proc/self/stat") as f:
        start_ticks = int(f.read().rsplit(")", 1)[1].split()[19])
    with open("/proc/uptime") as f:
        uptime = float(f.read().split()[0])
    return uptime - start_ticks / os.sysconf("SC_CLK_TCK")


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KB on Linux


def run_opti(opti_args: list[str]) -> dict[str, Any]:
    """The plain Opti script in this process."""
    t0 = time.perf_counter()
    sys.argv = ["opti_five_link.py", *opti_args]
    sys.path.insert(0, str(HERE))
    import opti_five_link  # noqa: PLC0415 (the worker imports it; the parent never does)

    out = opti_five_link.solve()
    return {"cost": out["cost"], "success": out["success"], "iterations": out["iterations"],
            "import_s": out["import_s"] + time.perf_counter() - t0 - out["total_s"],
            "solve_s": out["build_s"] + out["solve_s"],
            "solve_cpu_s": out["cpu_s"], "detail": out}


def run_gaitopt() -> dict[str, Any]:
    """gaitopt's public API in this process."""
    t0 = time.perf_counter()
    from gaitopt import GaitOptions, solve_gait  # noqa: PLC0415

    imported, c1 = time.perf_counter(), time.process_time()
    options = GaitOptions(speed=STEP_LENGTH / STEP_TIME, step_length=STEP_LENGTH,
                          single_support_fraction=1.0, knots={"single_support": KNOTS},
                          knot_spacing="uniform")
    gait = solve_gait("five-link", options)
    done = time.perf_counter()
    stages = gait.solver.get("stages", [])
    return {"cost": float(gait.cost_value), "success": bool(gait.success),
            "iterations": sum(int(s.get("iterations", 0)) for s in stages),
            "import_s": imported - t0, "solve_s": done - imported,
            "solve_cpu_s": time.process_time() - c1,
            "detail": {"stages": [(s.get("name"), s.get("iterations"),
                                   round(float(s.get("wall_time_s", 0.0)), 3))
                                  for s in stages]}}


def warm_up() -> None:
    """Import what both sides import (their byte code written)."""
    sys.path.insert(0, str(HERE))
    import casadi  # noqa: F401, PLC0415
    import opti_five_link  # noqa: F401, PLC0415

    import gaitopt.gait.api  # noqa: F401, PLC0415


def task(name: str, opti_args: list[str]) -> dict[str, Any]:
    """One measured run in a fresh worker process."""
    out = run_opti(opti_args) if name == "opti" else run_gaitopt()
    out.update(process_s=process_age_s(), process_cpu_s=time.process_time(),
               peak_rss_mb=peak_rss_mb(), pid=os.getpid())
    return out


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


FIGURES = (("process_s", "whole process, wall s"), ("process_cpu_s", "whole process, CPU s"),
           ("solve_s", "solve (build + IPOPT), wall s"), ("solve_cpu_s", "solve, CPU s"),
           ("import_s", "imports, wall s"), ("peak_rss_mb", "peak RSS, MB"))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs of each (alternating)")
    ap.add_argument("--agree", type=float, default=1e-4,
                    help="largest relative cost difference accepted")
    ap.add_argument("--opti-args", default="",
                    help="arguments of the Opti script, e.g. --opti-args=--expand")
    ap.add_argument("--no-bytecode", action="store_true",
                    help="the measured processes compile every source they import")
    args = ap.parse_args(argv)
    opti_args = args.opti_args.split()
    if not args.no_bytecode and (sys.flags.dont_write_bytecode
                                 or "PYTHONPYCACHEPREFIX" not in os.environ):
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env["PYTHONPYCACHEPREFIX"] = str(Path(tempfile.gettempdir()) / "gaitopt-bench-pyc")
        os.execve(sys.executable, [sys.executable, __file__, *sys.argv[1:]], env)
    print(f"load average before: {load()} ({os.cpu_count()} cores)")
    runs: dict[str, list[dict[str, Any]]] = {"opti": [], "gaitopt": []}
    ctx = get_context("spawn")
    with ProcessPoolExecutor(max_workers=1, mp_context=ctx, max_tasks_per_child=1) as pool:
        if not args.no_bytecode:  # byte code written, unmeasured
            pool.submit(warm_up).result()
        for i in range(args.repeat):
            order = ("opti", "gaitopt") if i % 2 == 0 else ("gaitopt", "opti")
            for name in order:
                out = pool.submit(task, name, opti_args).result()
                runs[name].append(out)
                print(f"  {name:8s} run {i + 1}: process {out['process_s']:.2f} s "
                      f"({out['process_cpu_s']:.2f} CPU), solve {out['solve_s']:.2f} s "
                      f"({out['solve_cpu_s']:.2f} CPU), imports {out['import_s']:.2f} s, "
                      f"{out['iterations']} it, J {out['cost']:.6f}, "
                      f"{'ok' if out['success'] else 'FAILED'}, peak RSS "
                      f"{out['peak_rss_mb']:.0f} MB; load {load()}", flush=True)
            if i == 0:
                a, b = runs["opti"][0]["cost"], runs["gaitopt"][0]["cost"]
                rel = abs(a - b) / abs(a)
                print(f"costs: Opti {a:.8f}, gaitopt {b:.8f}, relative difference {rel:.1e} "
                      f"(accepted: {args.agree:g})")
                if not (runs["opti"][0]["success"] and runs["gaitopt"][0]["success"]
                        and rel <= args.agree):
                    print("the two optima differ (or a solve failed): no times compared")
                    return 1
    print(f"\ngaitopt stages (last run): {runs['gaitopt'][-1]['detail']['stages']}")
    print(f"\n| figure (median of {args.repeat}) | Opti | gaitopt | gaitopt / Opti |")
    print("| --- | ---: | ---: | ---: |")
    for key, label in FIGURES:
        o = statistics.median(r[key] for r in runs["opti"])
        g = statistics.median(r[key] for r in runs["gaitopt"])
        print(f"| {label} | {o:.2f} | {g:.2f} | {g / o:.2f} |")
    print(f"target: gaitopt / Opti <= {TARGET} (goal {GOAL}); load average after: {load()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
