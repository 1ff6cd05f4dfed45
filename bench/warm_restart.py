"""The warm start's barrier, measured: a restart from a gait file's NLP point and multipliers
(stage ``warm start`` on the file's own grid) with IPOPT's adaptive barrier (the default,
``gaitopt.gait.solve.stages.RESTART_OPTIONS``) against the monotone barrier alone
(``solve_walking(adaptive_restart=False)``, the code before), in one process, alternately.

Per model: a cold ``gaitopt solve --model M --speed 60m/min`` process (unmeasured; the
command's defaults: refined to the accuracy, on the seven-link the released phase shares)
writes the file; then for each speed factor
(``--factors``, default 0.8-1.5 times) both settings restart from the file's point
(:func:`gaitopt.gait.api.restart_point`) on the file's grid, ``--repeat`` times each (the first
round is a warm-up, unmeasured: it builds the transcription and loads the point libraries).
Printed per case: the stages and their iterations, the seconds in the stages (median), the
cost and the relative difference of the two costs; then the sums, their ratio and the peak
resident set size of the process.

    PYTHONPATH=src python bench/warm_restart.py [--models five-link seven-link]
        [--factors 0.8 0.9 0.95 1.05 1.1 1.2 1.5] [--repeat 3]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as the gaitopt command runs

import argparse  # noqa: E402
import resource  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from gaitopt import Gait, GaitOptions  # noqa: E402
from gaitopt.gait.api import as_model, restart_point  # noqa: E402
from gaitopt.gait.options.model_defaults import options_for_model  # noqa: E402
from gaitopt.gait.solve.staged import solve_walking  # noqa: E402

REFERENCE_SPEED = 1.0  # m/s (60 m/min)
SETTINGS = {"adaptive": True, "monotone": False}


def knots_of(gait: Any) -> tuple[int, ...]:
    """The grid the file's answer was solved on (its accuracy record's knots per phase)."""
    return tuple(int(k) for k in gait.solver["accuracy"]["knots"].values())


def one(model: Any, options: GaitOptions, start: Any, adaptive: bool) -> dict[str, Any]:
    run = solve_walking(model, options, warm_start=start, adaptive_restart=adaptive)
    return {"stages": sum(s.wall_time_s for s in run.stages),
            "iterations": "+".join(str(s.iterations) for s in run.stages),
            "total_it": sum(s.iterations for s in run.stages),
            "cost": run.result.objective, "success": run.success}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--models", nargs="+", default=["five-link", "seven-link"])
    parser.add_argument("--factors", nargs="+", type=float,
                        default=[0.8, 0.9, 0.95, 1.05, 1.1, 1.2, 1.5])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"load average before: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    for name in args.models:
        model = as_model(name)
        path = Path(tempfile.mkdtemp(prefix="gaitopt-bench-restart-")) / f"{name}.gait.json"
        subprocess.run([sys.executable, "-m", "gaitopt", "solve", "--model", name, "--speed",
                        f"{REFERENCE_SPEED * 60:g}m/min", "-o", str(path)], check=True,
                       stdout=subprocess.DEVNULL)
        gait = Gait.load(path)
        knots = knots_of(gait)
        print(f"\n## {name}: restarts from its {REFERENCE_SPEED * 60:.0f} m/min optimum "
              f"(J {gait.cost_value:.6f}) on its grid {'+'.join(map(str, knots))}\n")
        print("| speed | adaptive: it | s | monotone: it | s | ratio | cost (adaptive) "
              "| rel. difference |")
        print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        sums = {k: 0.0 for k in SETTINGS}
        its = {k: 0 for k in SETTINGS}
        for factor in args.factors:
            given = GaitOptions(speed=REFERENCE_SPEED * factor, knots=knots)
            if gait.options.get("free_phase_fractions") is True:  # as solve_gait does
                given = given.replace(free_phase_fractions=True)
            options = options_for_model(model, given)
            start = restart_point(model, options, gait)
            if start is None:
                print(f"| {factor:.2f}x | the file's point does not fit |")
                continue
            rows: dict[str, list[dict[str, Any]]] = {k: [] for k in SETTINGS}
            for rep in range(args.repeat + 1):
                order = list(SETTINGS.items())
                for key, adaptive in (order if rep % 2 else order[::-1]):
                    row = one(model, options, start, adaptive)
                    if rep:  # the first round builds and loads: unmeasured
                        rows[key].append(row)
            med = {k: statistics.median(r["stages"] for r in rows[k]) for k in SETTINGS}
            a, m = rows["adaptive"][-1], rows["monotone"][-1]
            for k in SETTINGS:
                sums[k] += med[k]
                its[k] += rows[k][-1]["total_it"]
            diff = (a["cost"] - m["cost"]) / abs(m["cost"])
            flag = "" if a["success"] and m["success"] else \
                f" (success: adaptive {a['success']}, monotone {m['success']})"
            print(f"| {factor:.2f}x | {a['iterations']} | {med['adaptive']:.3f} | "
                  f"{m['iterations']} | {med['monotone']:.3f} | "
                  f"{med['adaptive'] / med['monotone']:.2f} | {a['cost']:.6f} | "
                  f"{diff:.1e}{flag} |", flush=True)
        if sums["monotone"] > 0:
            print(f"| sum | {its['adaptive']} | {sums['adaptive']:.3f} | {its['monotone']} | "
                  f"{sums['monotone']:.3f} | {sums['adaptive'] / sums['monotone']:.2f} | | |")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\npeak RSS {peak:.0f} MB; load average after: "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
