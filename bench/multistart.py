"""Does a single cold solve reach the sweep's optimum, and does multistart fix the misses?

For each variant and speed: the sweep's cost (``gaitopt sweep``'s continuation in speed, run
here in this process on the same grid and form: the reference, the best known optimum), a
cold solve from scratch (``GaitOptions(multistart=False)``), and a cold solve with
``multistart=True`` (every naive guess and the continuation in speed from 12 m/min, the
lowest coarse optimum kept), each with its wall time. A cold solve "reaches" the sweep when
its cost is within ``--within`` (0.1 %) of the sweep's (or below it).

``--grid-json FILE`` (the ``--json`` of ``bench/gait_grid.py``, cold solves of the whole
grid) compares those cold costs with the sweep's at every point instead, without solving
them again.

Run: ``python bench/multistart.py [--speeds 45 57 60] [--variants ...] [--knots 16,6]
[--transcription T] [--grid-json FILE]``
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.robot import load_model
from gaitopt.study.driver import run_sweep
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import VARIANTS

FLAGS = {"ankle+impulse": (True, True), "ankle": (True, False), "impulse": (False, True),
         "plain": (False, False)}


def load_average() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def sweep_costs(base: GaitOptions, speeds: list[float], variants: list[str]
                ) -> dict[tuple[str, float], float]:
    """The sweep's cost by (variant, speed m/min): a sweep of every speed 3..max(speeds) in
    steps of 3 m/min and the requested ones (the chains start at 12 m/min as the study's)."""
    grid = sorted({*range(3, int(max(speeds)) + 1, 3), *speeds})
    spec = SweepSpec(model=load_model("five-link"), speeds=tuple(v / 60.0 for v in grid),
                     variants=tuple(v for v in VARIANTS if v in variants), free_speed=False,
                     base=base)
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-ms-") as tmp:
        report = run_sweep(spec, Path(tmp) / "sweep", workers=0)
    return {(o.row.variant, round(o.row.speed_m_min, 6)): o.row.cost
            for o in report.outcomes if o.row.success}


def compare_grid(grid: list[dict[str, float]], swept: dict[tuple[str, float], float],
                 within: float) -> None:
    """The cold costs of ``grid`` against the sweep's: every point above it by more than
    ``within``, and the count."""
    print("\n| variant | speed (m/min) | sweep J | cold J | cold / sweep - 1 |")
    print("|:---|---:|---:|---:|---:|")
    misses = 0
    for p in grid:
        ref = swept.get((str(p["variant"]), round(float(p["speed_m_min"]), 6)), float("nan"))
        rel = float(p["cost"]) / ref - 1.0
        if not rel <= within:
            misses += 1
            print(f"| {p['variant']} | {p['speed_m_min']:g} | {ref:.2f} | {p['cost']:.2f} | "
                  f"{100 * rel:+.3f} % |")
    lowest = min(float(p["cost"]) / swept[(str(p["variant"]), round(float(p["speed_m_min"]),
                                                                    6))] - 1.0
                 for p in grid if (str(p["variant"]), round(float(p["speed_m_min"]), 6))
                 in swept)
    print(f"\n{misses}/{len(grid)} cold solves above the sweep by more than "
          f"{100 * within:g} %; the largest gain of a cold solve over the sweep: "
          f"{-100 * lowest:.3f} %")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--speeds", type=float, nargs="+", default=[45.0, 57.0, 60.0])
    parser.add_argument("--variants", nargs="+", default=list(FLAGS), choices=list(FLAGS))
    parser.add_argument("--knots", default=None, help="single,double (default: the default)")
    parser.add_argument("--transcription", default=None, help="default: the default")
    parser.add_argument("--within", type=float, default=1e-3,
                        help="relative cost tolerance of 'reaches the sweep' (0.1 %%)")
    parser.add_argument("--grid-json", type=Path, default=None,
                        help="cold solves of bench/gait_grid.py --json to compare instead")
    args = parser.parse_args(argv)
    changes: dict[str, object] = {}
    if args.knots:
        k = [int(v) for v in args.knots.split(",")]
        changes["knots"] = (k[0], k[1])
    if args.transcription:
        changes["transcription"] = args.transcription
    base = GaitOptions(**changes)  # type: ignore[arg-type]
    print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores); "
          f"grid {base.knots[0]}+{base.knots[1]}, {base.transcription}")
    grid = json.loads(args.grid_json.read_text()) if args.grid_json else None
    speeds = sorted({p["speed_m_min"] for p in grid}) if grid else args.speeds
    start = time.perf_counter()
    swept = sweep_costs(base, speeds, args.variants)
    print(f"sweep (reference costs): {time.perf_counter() - start:.1f} s", flush=True)
    if grid is not None:
        compare_grid(grid, swept, args.within)
        return
    model = load_model("five-link")
    print("\n| variant | speed (m/min) | sweep J | cold J | cold / sweep - 1 | cold wall (s) "
          "| multistart J | multistart / sweep - 1 | multistart wall (s) |")
    print("|:---|---:|---:|---:|---:|---:|---:|---:|---:|")
    misses = {"cold": 0, "multistart": 0}
    walls = {"cold": 0.0, "multistart": 0.0}
    for variant in args.variants:
        ankle, impulse = FLAGS[variant]
        for speed in args.speeds:
            ref = swept.get((variant, round(speed, 6)), float("nan"))
            cells = [variant, f"{speed:g}", f"{ref:.2f}"]
            for kind in ("cold", "multistart"):
                options = base.replace(speed=speed / 60.0, ankle=ankle, impulse=impulse,
                                       multistart=kind == "multistart")
                t0 = time.perf_counter()
                sol = solve_staged_run(model, options)
                wall = time.perf_counter() - t0
                cost = sol.result.objective if sol.success else float("nan")
                rel = cost / ref - 1.0
                if not (rel <= args.within):
                    misses[kind] += 1
                walls[kind] += wall
                cells += [f"{cost:.2f}" if sol.success else "FAIL", f"{100 * rel:+.3f} %",
                          f"{wall:.2f}"]
            print("| " + " | ".join(cells) + " |", flush=True)
    n = len(args.variants) * len(args.speeds)
    print(f"\nmisses (cost above the sweep's by more than {100 * args.within:g} %): cold "
          f"{misses['cold']}/{n}, multistart {misses['multistart']}/{n}; total wall: cold "
          f"{walls['cold']:.1f} s, multistart {walls['multistart']:.1f} s")
    print(f"load average after: {load_average()}")


if __name__ == "__main__":
    main()
