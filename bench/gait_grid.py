"""The issue's convergence grid: every speed 3, 6, ..., 60 m/min for each of the four variants,
solved from scratch with the default solve (naive guess and automatic continuation, no warm
start), then checked with ``verify``.

Prints one Markdown table per variant (speed, success, wall time, IPOPT iterations over all
stages, the stages run, step length, cost, verify outcome) and a summary (success rate, verify
pass rate, median and largest time per variant), with the load average before and after: the
machine is shared, so times are noisy. The first point of each variant also builds its NLP
(a few seconds); the later points of the variant reuse it (the process-wide cache).

Verify column: ``pass``, or the failed checks, looked up by stable id (:data:`SHORT`:
``interval`` re-integration per interval, ``limits`` joint limits between knots, ``force``
normal force on the dense samples; other checks by their id),
``force@strike`` the force check failed only because of the dense sample at the heel-strike
instant, the verify bug recorded in tests/gait/test_verify.py: recomputed with each sample in
its own phase, no normal force is negative).

Run: ``python bench/gait_grid.py [--speeds 3 6 ...] [--variants plain ankle] [--json FILE]
[--transcription hermite-simpson-separated] [--knot-spacing cosine]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from gaitopt.analysis.verify import LIMITS, verify_gait
from gaitopt.dynamics.functions import contact_dynamics_function
from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import KNOT_SPACINGS, TRANSCRIPTIONS, GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run

VARIANTS = {
    "ankle+impulse": {"ankle": True, "impulse": True},
    "ankle": {"ankle": True, "impulse": False},
    "impulse": {"ankle": False, "impulse": True},
    "plain": {"ankle": False, "impulse": False},
}
SPEEDS_M_MIN = tuple(range(3, 61, 3))
#: Short labels of the verify checks by stable id (``gaitopt.analysis.verify.CHECKS``); a
#: check without a label here is shown by its id.
SHORT = {
    "integration.interval": "interval",
    "samples.normal_force": "force",
    "contacts.position": "tips",
    "events.maps": "events",
    "events.periodicity": "periodic",
    "events.periodic_controls": "periodic-u",
    "bounds.torque": "torque",
    "bounds.joints_knots": "limits@knots",
    "bounds.joints_samples": "limits",
    "swing.clearance": "clearance",
    "cost.recomputed": "cost",
}


@dataclass(frozen=True)
class Point:
    variant: str
    speed_m_min: float
    success: bool
    status: str
    failed_stage: str
    wall_time_s: float
    iterations: int
    stages: int
    step_length: float
    impulse: float
    cost: float
    verify: str


def load_average() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def verify_summary(gait: Gait) -> str:
    report = verify_gait(gait)
    failed = report.failed_ids
    if not failed:
        return "pass"
    names = [SHORT.get(n, n) for n in failed]
    weight = gait.model.total_mass * float(np.hypot(*gait.model.gravity))
    if ("samples.normal_force" in failed
            and lowest_force_by_phase(gait) >= -LIMITS["samples.normal_force"] * weight):
        names[failed.index("samples.normal_force")] = "force@strike"
    return " ".join(names)


def lowest_force_by_phase(gait: Gait) -> float:
    """Smallest normal force (N) on the dense samples, each sample with its own phase's
    contacts (single support up to the heel strike inclusive, double support after)."""
    s = gait.samples
    strike = next(e for e in gait.events if e.name == "heel_strike").t
    lowest = np.inf
    for i, ph in enumerate(gait.phases):
        mask = (s.t <= strike) if i == 0 else (s.t > strike)
        if not mask.any():
            continue
        dyn = contact_dynamics_function(gait.model, ph.contacts, inputs="u")
        n = int(mask.sum())
        forces = np.asarray(dyn.map(n)(s.q[mask].T, s.qd[mask].T, s.u[mask].T)[1], dtype=float)
        lowest = min(lowest, float(np.min(forces[1::2, :])))
    return lowest


def solve_point(variant: str, speed_m_min: float, *, check: bool,
                transcription: str = "hermite-simpson",
                knot_spacing: str = GaitOptions().knot_spacing,
                formulation: str = GaitOptions().formulation) -> Point:
    options = GaitOptions(speed=speed_m_min / 60.0, transcription=transcription,  # type: ignore[arg-type]
                          knot_spacing=knot_spacing,  # type: ignore[arg-type]
                          formulation=formulation,  # type: ignore[arg-type]
                          **VARIANTS[variant])
    start = time.perf_counter()
    solution = solve_staged_run("five-link", options)
    wall = time.perf_counter() - start
    failed = solution.failed_stage
    nan = float("nan")
    status, stage = solution.result.status, failed.name if failed else ""
    try:
        gait = gait_from_run(solution) if solution.success else None
    except MotionOutOfReachError:
        gait, status, stage = None, "motion out of reach between knots", "record"
    return Point(
        variant=variant, speed_m_min=speed_m_min, success=gait is not None,
        status=status, failed_stage=stage,
        wall_time_s=wall, iterations=sum(s.iterations for s in solution.stages),
        stages=len(solution.stages),
        step_length=gait.step_length if gait else nan,
        impulse=gait.parameters["liftoff_impulse"] if gait else nan,
        cost=gait.cost_value if gait else nan,
        verify=(verify_summary(gait) if check else "-") if gait else "-")


def variant_table(points: list[Point]) -> str:
    lines = ["| speed (m/min) | converged | wall (s) | iterations | stages | step (m) | "
             "impulse (N s) | cost (N^2 m s) | verify |",
             "|---:|:---|---:|---:|---:|---:|---:|---:|:---|"]
    for p in points:
        ok = "yes" if p.success else f"NO ({p.failed_stage}: {p.status})"
        lines.append(f"| {p.speed_m_min:g} | {ok} | {p.wall_time_s:.2f} | {p.iterations} | "
                     f"{p.stages} | {p.step_length:.4f} | {p.impulse:.3g} | {p.cost:.1f} | "
                     f"{p.verify} |")
    return "\n".join(lines)


def summary_table(points: list[Point], variants: list[str]) -> str:
    lines = ["| variant | converged | verify passes | verify passes but for force@strike | "
             "median wall (s) | largest wall (s) | total (s) |",
             "|:---|---:|---:|---:|---:|---:|---:|"]
    for v in [*variants, "all"]:
        pts = [p for p in points if v in ("all", p.variant)]
        n = len(pts)
        ok = sum(p.success for p in pts)
        passed = sum(p.verify == "pass" for p in pts)
        but_bug = sum(p.verify in ("pass", "force@strike") for p in pts)
        walls = [p.wall_time_s for p in pts]
        lines.append(f"| {v} | {ok}/{n} ({100 * ok / n:.0f} %) | {passed}/{n} | {but_bug}/{n} "
                     f"| {statistics.median(walls):.2f} | {max(walls):.2f} | {sum(walls):.1f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--speeds", type=float, nargs="+", default=list(SPEEDS_M_MIN),
                        help="speeds in m/min")
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--no-verify", action="store_true", help="skip the verify column")
    parser.add_argument("--json", type=Path, help="also write the points as JSON")
    parser.add_argument("--transcription", default=GaitOptions().transcription,
                        choices=TRANSCRIPTIONS,
                        help="GaitOptions.transcription of every point (default: the default)")
    parser.add_argument("--knot-spacing", default=GaitOptions().knot_spacing,
                        choices=KNOT_SPACINGS,
                        help="GaitOptions.knot_spacing of every point (default: the default)")
    parser.add_argument("--formulation", default=GaitOptions().formulation,
                        choices=("reduced", "full"),
                        help="GaitOptions.formulation of every point (default: the default)")
    args = parser.parse_args(argv)

    print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores)")
    points: list[Point] = []
    for variant in args.variants:
        rows = []
        for speed in args.speeds:
            point = solve_point(variant, speed, check=not args.no_verify,
                                transcription=args.transcription,
                                knot_spacing=args.knot_spacing,
                                formulation=args.formulation)
            rows.append(point)
            print(f"  {variant:<14} {speed:5.1f} m/min  {'ok ' if point.success else 'FAIL'}"
                  f" {point.wall_time_s:6.2f} s  verify {point.verify}", flush=True)
        points += rows
        print(f"\n### {variant}\n\n{variant_table(rows)}\n", flush=True)
    print(f"### summary\n\n{summary_table(points, args.variants)}\n")
    print(f"load average after: {load_average()}")
    if args.json:
        args.json.write_text(json.dumps([asdict(p) for p in points], indent=1))


if __name__ == "__main__":
    main()
