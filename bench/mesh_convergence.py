"""Grid convergence of the walking problem per control model (and swing clearance).

For every control model and grid it solves the default problem (ankle+impulse, five-link) at
12 m/min, then the speed-free optimum warm-started from it on the same grid, and prints one
Markdown row per grid: cost and step length at 12 m/min, the speed-free speed, step length
and cost, the largest collocation error estimate and where it sits (phase, interval, and the
interval's position in the phase), and the wall time. ``--clearance`` adds a swing-clearance
profile (m), ``--profile`` its shape. ``--json FILE`` appends the rows as JSON lines.

Models: ``paper`` (controls continuous at the heel strike and periodic), ``states-only``
(the paper's model with ``periodic_controls=False``), ``jumps`` (no control linkages).

Run: ``python bench/mesh_convergence.py [--models paper jumps] [--grids 8,5 16,6]
[--clearance 0.02] [--json FILE]``
"""

from __future__ import annotations

import argparse
import json
import os
import time
from typing import Any

import numpy as np

from gaitopt.gait.options import GaitOptions
from gaitopt.gait.solve import solve_walking
from gaitopt.ocp import Result
from gaitopt.robot import load_model

MODELS: dict[str, dict[str, Any]] = {
    "paper": {"control_model": "paper"},
    "states-only": {"control_model": "paper", "periodic_controls": False},
    "jumps": {"control_model": "jumps"},
}
GRIDS = ((8, 5), (16, 6), (24, 8), (40, 10), (80, 20))


def worst_interval(result: Result) -> str:
    """Where the largest error estimate sits: phase, interval k of N, position tau_k."""
    best = max(((float(np.max(ph.error)), ph.name, int(np.argmax(ph.error)), ph)
                for ph in result.phases), key=lambda e: e[0])
    err, name, k, ph = best
    return f"{name}[{k}/{ph.error.size}] tau {ph.tau[k]:.2f}"


def row(model: str, grid: tuple[int, int], clearance: float | None,
        profile: str = "quartic") -> dict[str, Any]:
    robot = load_model("five-link")
    options = GaitOptions(knots=grid, swing_clearance=clearance,
                          clearance_profile=profile,  # type: ignore[arg-type]
                          **MODELS[model])
    start = time.perf_counter()
    fixed = solve_walking(robot, options)
    out: dict[str, Any] = {"model": model, "grid": list(grid), "clearance": clearance,
                           "profile": profile, "success": fixed.success}
    if fixed.success:
        r = fixed.result
        out.update(cost=r.objective, step=r.parameters["step_length"],
                   error=r.max_error, where=worst_interval(r))
        free = solve_walking(robot, options.replace(speed=None), warm_start=r)
        out["free_success"] = free.success
        if free.success:
            f = free.result
            out.update(free_speed=f.parameters["speed"], free_step=f.parameters["step_length"],
                       free_cost=f.objective, free_error=f.max_error)
    out["wall_s"] = time.perf_counter() - start
    return out


def line(r: dict[str, Any]) -> str:
    def num(key: str, fmt: str, scale: float = 1.0) -> str:
        v = r.get(key)
        return format(v * scale, fmt) if isinstance(v, float) else "failed"

    return (f"| {r['model']} | {r['grid'][0]}+{r['grid'][1]} | {num('cost', '.2f')} | "
            f"{num('step', '.4f')} | {num('free_speed', '.2f', 60.0)} | {num('free_step', '.4f')}"
            f" | {num('free_cost', '.2f')} | {num('error', '.1e')} | {r.get('where', '-')} | "
            f"{r['wall_s']:.0f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", nargs="+", default=list(MODELS), choices=list(MODELS))
    ap.add_argument("--grids", nargs="+", default=[f"{a},{b}" for a, b in GRIDS])
    ap.add_argument("--clearance", type=float, default=None)
    ap.add_argument("--profile", default="quartic", choices=["quartic", "parabola"])
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    grids = [tuple(int(v) for v in g.split(",")) for g in args.grids]
    print(f"load average {os.getloadavg()[0]:.2f}; clearance {args.clearance} "
          f"({args.profile})")
    print("| controls | knots | cost @ 12 m/min | step (m) | free: speed (m/min) | free: step "
          "(m) | free: cost | max error | largest error at | wall (s) |")
    print("|:--|--:|--:|--:|--:|--:|--:|--:|:--|--:|")
    for model in args.models:
        for grid in grids:
            r = row(model, (grid[0], grid[1]), args.clearance, args.profile)
            print(line(r), flush=True)
            if args.json:
                with open(args.json, "a") as fh:
                    fh.write(json.dumps(r) + "\n")


if __name__ == "__main__":
    main()
