"""Benchmark of memory: one process solves 16 differently shaped paper-grid problems through
the public API (``solve_gait``), as a notebook user who sweeps variants does.

The 16 problems: ankle torques on/off x liftoff impulse on/off x periodic controls on/off x
the two formulations (reduced, full), each on the paper's 8 + 5 grid (the compressed form:
the largest NLPs per knot) at 12 m/min. Each run is a fresh process; the peak resident set
size, the resident size after the loop, and the wall time are printed beside a reference
measured in the same run: the same loop with an unbounded cache (``GAITOPT_MEMORY_MB`` huge,
every transcription kept, as before the cache was bounded in bytes).

    PYTHONPATH=src python bench/memory.py [--budget-mb 640] [--problems 16]
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import sys
import time

MB = 2**20


def child(count: int) -> None:
    """Solve the loop in this process; print one JSON line of figures."""
    from gaitopt import GaitOptions, load_model, solve_gait
    from gaitopt.process_memory import peak_resident_bytes, resident_bytes

    model = load_model("five-link")
    variants = list(itertools.product((True, False), (True, False), (True, False),
                                      ("reduced", "full")))[:count]
    start = time.perf_counter()
    peaks, failed = [], 0
    for ankle, impulse, periodic, formulation in variants:
        options = GaitOptions.paper(ankle=ankle, impulse=impulse, periodic_controls=periodic,
                                    formulation=formulation)
        gait = solve_gait(model, options)
        failed += not gait.success
        peaks.append(resident_bytes() / MB)
    print(json.dumps({"wall_s": time.perf_counter() - start, "failed": failed,
                      "peak_mb": peak_resident_bytes() / MB, "end_mb": resident_bytes() / MB,
                      "after_each_mb": peaks}))


def run(budget_mb: float, count: int) -> dict[str, float]:
    env = {**os.environ, "GAITOPT_MEMORY_MB": str(budget_mb)}
    out = subprocess.run([sys.executable, __file__, "--child", str(count)], env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--budget-mb", type=float, default=None,
                    help="the budget to measure (default: gaitopt's default)")
    ap.add_argument("--problems", type=int, default=16)
    ap.add_argument("--child", type=int, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child is not None:
        child(args.child)
        return
    from gaitopt.process_memory import DEFAULT_BUDGET_MB

    budget = args.budget_mb if args.budget_mb is not None else DEFAULT_BUDGET_MB
    print(f"{args.problems} paper-grid problems through solve_gait, one process each run")
    rows = [("unbounded cache (reference)", run(1e9, args.problems)),
            (f"budget {budget:g} MB", run(budget, args.problems))]
    print(f"{'run':32s} {'peak RSS MB':>12s} {'RSS at end MB':>14s} {'wall s':>8s} "
          f"{'failed':>7s}")
    for name, r in rows:
        print(f"{name:32s} {r['peak_mb']:12.0f} {r['end_mb']:14.0f} {r['wall_s']:8.1f} "
              f"{int(r['failed']):7d}")
    ref, new = rows[0][1], rows[1][1]
    print(f"ratio to the reference: peak RSS {new['peak_mb'] / ref['peak_mb']:.2f}, "
          f"wall time {new['wall_s'] / ref['wall_s']:.2f}")


if __name__ == "__main__":
    main()
