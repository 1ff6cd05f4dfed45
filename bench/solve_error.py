"""The default single solve's cost error estimate against a much finer grid.

For each ``--speeds`` (m/min) x ``--variants`` point it runs the solve ``gaitopt solve`` runs
(the default options; multistart as the CLI chooses it: on at 15 m/min or more from
12 m/min), reads the gait's ``solver.accuracy`` (the estimate: 3 x the change to the check
grid 24 + 8), then solves the same problem on cosine-spaced ``--limit`` knots (default
80 + 20 and 120 + 30, each warm-started from the grid before) for the fine-grid limit, and
prints one Markdown row per point: the cost, the estimate, the true distance to the finest
grid, whether the estimate bounds it, the step length and its distance, the old estimate
(the change from the 8 + 5 stage) and the solve's wall time (whole solve, and the check
stage alone). ``--knot-spacing uniform`` measures uniform knots instead.

Run: ``python bench/solve_error.py [--speeds 12 30 60] [--variants ankle+impulse plain]
[--knot-spacing cosine] [--limit 80,20 120,30]``
"""

from __future__ import annotations

import argparse
import os
import time

from gaitopt.cli.gait import multistart_default
from gaitopt.gait.options.gait_options import KNOT_SPACINGS, GaitOptions
from gaitopt.gait.solve.accuracy import accuracy_record
from gaitopt.gait.solve.staged import solve_walking
from gaitopt.robot import load_model
from gaitopt.study.summary import variant_flags


def knots(text: str) -> tuple[int, int]:
    single, double = (int(k) for k in text.split(","))
    return single, double


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speeds", nargs="+", type=float, default=[12.0, 30.0, 60.0])
    parser.add_argument("--variants", nargs="+", default=["ankle+impulse", "plain"])
    parser.add_argument("--knot-spacing", choices=list(KNOT_SPACINGS), default="cosine")
    parser.add_argument("--limit", nargs="+", type=knots, default=[(80, 20), (120, 30)])
    args = parser.parse_args()
    model = load_model("five-link")
    print(f"load average before: {os.getloadavg()[0]:.2f}; knot spacing {args.knot_spacing}; "
          f"limit: cosine {'+'.join(map(str, args.limit[-1]))}")
    print("| variant | speed (m/min) | cost | estimate | % of J | limit | distance | bounds | "
          "step (m) | step on limit | old estimate (from 8+5) | solve (s) | check (s) |")
    print("|:--|--:|--:|--:|--:|--:|--:|:--|--:|--:|--:|--:|--:|")
    worst = 0.0
    for variant in args.variants:
        ankle, impulse = variant_flags(variant)
        for speed in args.speeds:
            options = GaitOptions(speed=speed / 60.0, ankle=ankle, impulse=impulse,
                                  knot_spacing=args.knot_spacing,
                                  multistart=multistart_default(speed / 60.0, "reduced"))
            start = time.perf_counter()
            solution = solve_walking(model, options)
            wall = time.perf_counter() - start
            if not solution.success:
                print(f"| {variant} | {speed:g} | failed: {solution.result.status} |")
                continue
            acc = accuracy_record(solution)
            result = fine = solution.result
            for grid in args.limit:
                finer = solve_walking(model, options.replace(knots=grid, knot_spacing="cosine",
                                                             multistart=False),
                                      warm_start=fine)
                if not finer.success:
                    break
                fine = finer.result
            limit = fine.objective
            distance = result.objective - limit
            estimate = acc["cost_error"]
            bounds = estimate is not None and abs(distance) <= abs(estimate)
            worst = max(worst, abs(distance) / abs(estimate) if estimate else float("inf"))
            old = (abs(result.objective - acc["previous_cost"]) / result.objective
                   if acc["previous_cost"] is not None else float("nan"))
            check = sum(s.wall_time_s for s in solution.stages if s.name.endswith("check grid"))
            est = "n/a" if estimate is None else f"{estimate:+.3f}"
            rel = "n/a" if estimate is None else f"{100 * acc['cost_error_relative']:.2f} %"
            print(f"| {variant} | {speed:g} | {result.objective:.3f} | {est} | {rel} | "
                  f"{limit:.3f} | {100 * distance / limit:+.2f} % | "
                  f"{'yes' if bounds else 'NO'} | {result.parameters['step_length']:.4f} | "
                  f"{fine.parameters['step_length']:.4f} | {100 * old:.2f} % | {wall:.2f} | "
                  f"{check:.2f} |", flush=True)
    print(f"largest distance / |estimate|: {worst:.2f} (<= 1: the estimate bounds every point); "
          f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
