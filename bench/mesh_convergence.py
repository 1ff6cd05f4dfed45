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

``--study DIR`` measures the converged values of a study (``gaitopt study -o DIR``) instead:
for each ``--variants`` x ``--speeds`` point (m/min, or ``free`` for the speed-free optimum)
it takes the point's gait from the study's finest grid (its deepest refinement sweep, else its check
sweep), solves the same problem warm-started from it on each ``--grids`` grid in turn (each
from the previous; ``--spacing`` uniform or cosine knots, default the study's), and prints
each grid's values and their distance to the finest grid (cost relative).
Run: ``python bench/mesh_convergence.py --study out/study --speeds 12 36 60 free
--grids 40,10 80,20``
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from gaitopt.gait.api import guess_from_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.staged import solve_walking
from gaitopt.ocp import Result
from gaitopt.robot import load_model
from gaitopt.study.grid_error import CHECK_DIR, MAX_REFINE_LEVELS, refine_dir_name, sweep_grid
from gaitopt.study.summary import SUMMARY_FILE, VARIANTS, read_summary

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
    # Uniform knots, as the tables of docs/walking.md section 6 were measured (the default
    # spacing is cosine since 2026-12-02).
    options = GaitOptions(knots=grid, swing_clearance=clearance, knot_spacing="uniform",
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


def study_grids(study: Path) -> list[tuple[str, Path]]:
    """The study's sweeps, coarse to fine: (``16+6``, directory) for the main, check and
    refinement sweeps (every level) that exist."""
    out = []
    levels = [study / refine_dir_name(k) for k in range(1, MAX_REFINE_LEVELS + 1)]
    for d in (study, study / CHECK_DIR, *levels):
        grid = sweep_grid(d)
        if grid is not None and (d / SUMMARY_FILE).exists():
            out.append((f"{grid[0][0]}+{grid[0][1]}", d))
    return out


def study_point(study: Path, variant: str, speed: str, grids: list[tuple[int, int]],
                spacing: str | None = None) -> dict[str, Any]:
    """One point of ``--study``: its values on the study's grids and on ``grids``."""
    robot = load_model("five-link")
    out: dict[str, Any] = {"variant": variant, "speed": speed, "values": {}}
    start_gait = None
    for label, d in study_grids(study):
        rows = [r for r in read_summary(d / SUMMARY_FILE) if r.variant == variant and r.success
                and (r.speed_mode == "free" if speed == "free" else
                     r.speed_mode == "fixed" and abs(r.speed_m_min - float(speed)) < 5e-3)]
        if rows:
            r = rows[0]
            out["values"][label] = (r.cost, r.speed_m_min, r.step_length)
            start_gait = Gait.load(d / r.file)
    if start_gait is None:
        return out
    options = GaitOptions.from_dict(dict(start_gait.options)).replace(
        speed=None if speed == "free" else float(speed) / 60.0)
    if spacing is not None:
        options = options.replace(knot_spacing=spacing)
    warm: Any = guess_from_gait(start_gait)
    for grid in grids:
        mark = time.perf_counter()
        sol = solve_walking(robot, options.replace(knots=grid), warm_start=warm)
        label = f"{grid[0]}+{grid[1]} {options.knot_spacing}"
        if sol.success:
            r = sol.result
            out["values"][label] = (r.objective, 60.0 * r.parameters["speed"],
                                    r.parameters["step_length"])
            warm = r
        else:
            out["values"][label] = None
        out.setdefault("wall_s", {})[label] = time.perf_counter() - mark
    return out


def study_lines(p: dict[str, Any]) -> list[str]:
    """Markdown rows of one ``--study`` point: each grid's values and distance to the finest."""
    values = [(g, v) for g, v in p["values"].items() if v is not None]
    if not values:
        return [f"| {p['variant']} | {p['speed']} | failed | | | | |"]
    ref = values[-1][1]
    lines = []
    for g, (cost, speed, step) in values:
        lines.append(f"| {p['variant']} | {p['speed']} | {g} | {cost:.2f} | "
                     f"{100 * (cost - ref[0]) / ref[0]:+.2f} % | {speed:.2f} | {step:.4f} |")
    return lines


def main_study(args: argparse.Namespace) -> None:
    grids = [(int(a), int(b)) for a, b in (g.split(",") for g in args.grids)]
    print(f"load average {os.getloadavg()[0]:.2f}; study {args.study}")
    print("| variant | speed (m/min) | knots | cost | to the finest | speed (m/min) | step (m) |")
    print("|:--|--:|--:|--:|--:|--:|--:|")
    for variant in args.variants:
        for speed in args.speeds:
            p = study_point(Path(args.study), variant, speed, grids, args.spacing)
            print("\n".join(study_lines(p)), flush=True)
            if args.json:
                with open(args.json, "a") as fh:
                    fh.write(json.dumps(p) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--study", default=None, help="measure this study's converged values")
    ap.add_argument("--variants", nargs="+", default=["ankle", "plain"], choices=VARIANTS)
    ap.add_argument("--speeds", nargs="+", default=["12", "36", "60", "free"],
                    help="with --study: speeds in m/min, or free")
    ap.add_argument("--spacing", default=None, choices=["uniform", "cosine"],
                    help="with --study: the knot spacing of --grids (default: the study's)")
    ap.add_argument("--models", nargs="+", default=list(MODELS), choices=list(MODELS))
    ap.add_argument("--grids", nargs="+", default=[f"{a},{b}" for a, b in GRIDS])
    ap.add_argument("--clearance", type=float, default=None)
    ap.add_argument("--profile", default="quartic", choices=["quartic", "parabola"])
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    if args.study is not None:
        if args.grids == ap.get_default("grids"):
            args.grids = ["40,10", "80,20"]
        main_study(args)
        return
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
