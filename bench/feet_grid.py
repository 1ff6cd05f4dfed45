"""The convergence grid of a model with feet: cold solves from the naive guess at a few speeds
and at the speed-free optimum, each checked with ``verify``.

By default the built-in ``seven-link`` model with the heel-toe walk on 24+16 knots, the paper's
cost, knees free to straighten, with and without the liftoff impulse (the seven-link ankles
are joints, so the ankle-torque switch of the five-link variants changes nothing here), at 12,
30, 45, 60 and 80 m/min and speed free. Prints a Markdown table (speed, converged, wall time,
IPOPT iterations over all stages, step length, cost, impulse, the failed verify checks by id)
and the load average before and after: the machine may be shared, so times are noisy. One
process: the first point of each variant also builds the NLP.

Run: ``python bench/feet_grid.py [--model seven-link] [--gait heel-toe] [--knots 24,16]
[--speeds 12 30 ...] [--no-free] [--set FIELD=VALUE ...] [--json FILE]``; ``--set`` passes any
other :class:`gaitopt.gait.options.gait_options.GaitOptions` field (a JSON value, e.g.
``--set min_stance_knee_flexion=0.1``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run

sys.path.insert(0, str(Path(__file__).resolve().parent))
from gait_grid import load_average  # noqa: E402  (the five-link grid's helpers)

VARIANTS = {"impulse": True, "no impulse": False}
SPEEDS_M_MIN = (12.0, 30.0, 45.0, 60.0, 80.0)


@dataclass(frozen=True)
class Point:
    variant: str
    speed: str
    success: bool
    status: str
    wall_time_s: float
    iterations: int
    speed_m_min: float
    step_length: float
    impulse: float
    cost: float
    verify: str


def solve_point(model: str, base: GaitOptions, variant: str, speed_m_min: float | None) -> Point:
    """One cold solve (``speed_m_min=None``: speed free) and its verify outcome."""
    options = base.replace(impulse=VARIANTS[variant],
                           speed=None if speed_m_min is None else speed_m_min / 60.0)
    start = time.perf_counter()
    solution = solve_staged_run(model, options)
    wall = time.perf_counter() - start
    nan = math.nan
    status = solution.result.status
    try:
        gait = gait_from_run(solution) if solution.success else None
    except MotionOutOfReachError:
        gait, status = None, "motion out of reach between knots"
    verdict = "-"
    if gait is not None:
        failed = verify_gait(gait).failed_ids
        verdict = " ".join(failed) if failed else "pass"
    return Point(variant=variant, speed="free" if speed_m_min is None else f"{speed_m_min:g}",
                 success=gait is not None, status=status, wall_time_s=wall,
                 iterations=sum(s.iterations for s in solution.stages),
                 speed_m_min=gait.speed * 60.0 if gait else nan,
                 step_length=gait.step_length if gait else nan,
                 impulse=gait.parameters["liftoff_impulse"] if gait else nan,
                 cost=gait.cost_value if gait else nan, verify=verdict)


def table(points: list[Point]) -> str:
    lines = ["| variant | speed (m/min) | converged | wall (s) | iterations | speed (m/min) | "
             "step (m) | impulse (N s) | cost | verify |",
             "|:---|---:|:---|---:|---:|---:|---:|---:|---:|:---|"]
    for p in points:
        ok = "yes" if p.success else f"NO ({p.status})"
        lines.append(f"| {p.variant} | {p.speed} | {ok} | {p.wall_time_s:.1f} | {p.iterations} "
                     f"| {p.speed_m_min:.1f} | {p.step_length:.3f} | {p.impulse:.3g} | "
                     f"{p.cost:.1f} | {p.verify} |")
    n = len(points)
    lines.append(f"\nconverged {sum(p.success for p in points)}/{n}, verify passes "
                 f"{sum(p.verify == 'pass' for p in points)}/{n}, total wall "
                 f"{sum(p.wall_time_s for p in points):.0f} s")
    return "\n".join(lines)


def parse_set(items: list[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise SystemExit(f"--set {item!r}: expected FIELD=VALUE")
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", default="seven-link")
    parser.add_argument("--gait", default="heel-toe")
    parser.add_argument("--knots", default="24,16", help="first phases' knots, e.g. 24,16")
    parser.add_argument("--speeds", type=float, nargs="+", default=list(SPEEDS_M_MIN))
    parser.add_argument("--no-free", action="store_true", help="skip the speed-free optimum")
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--set", dest="sets", action="append", default=[],
                        metavar="FIELD=VALUE", help="another GaitOptions field (JSON value)")
    parser.add_argument("--json", type=Path, help="also write the points as JSON")
    args = parser.parse_args(argv)
    knots = tuple(int(k) for k in args.knots.split(","))
    base = GaitOptions(gait=args.gait, formulation="full", knots=knots,
                       min_stance_knee_flexion=0.0, **parse_set(args.sets))
    print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores)")
    print(f"model {args.model}, gait {args.gait}, knots {args.knots}, options {args.sets}")
    points: list[Point] = []
    speeds: list[float | None] = [*args.speeds, *([] if args.no_free else [None])]
    for variant in args.variants:
        for speed in speeds:
            p = solve_point(args.model, base, variant, speed)
            points.append(p)
            print(f"  {variant:<10} {p.speed:>5} m/min  {'ok ' if p.success else 'FAIL'} "
                  f"{p.wall_time_s:7.1f} s  cost {p.cost:8.1f}  verify {p.verify}", flush=True)
    print(f"\n{table(points)}\n")
    print(f"load average after: {load_average()}")
    if args.json:
        args.json.write_text(json.dumps([asdict(p) for p in points], indent=1))


if __name__ == "__main__":
    main()
