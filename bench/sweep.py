"""Benchmark of a sweep: 4 variants x 20 speeds (3..60 m/min step 3) on local processes.

Measures, in one run: the wall time of the sweep from scratch (process start, transcription
builds, solves, file writes) and resumed (nothing left to solve), solves per minute, and where
the time goes (summed over the points: transcription builds, IPOPT, gait records in the
workers, gait file writes in the driver; process start measured separately), against
references measured in the same run: a worker pool's start-up and one transcription build in
this process. Target: under 60 s for the 80 points on the 2-core reference machine.

    PYTHONPATH=src python bench/sweep.py [--workers 2] [--speeds 3:60:3] [--free]
        [--start-methods forkserver,spawn] [--transcription T] [--reference main]
        [--grid paper|default]

``--reference main`` first runs the same benchmark on git revision ``main`` (its sources
extracted into a temporary folder, the same interpreter) with the paper's compressed form,
then this branch with ``--transcription`` (default: the separated form), and prints the
ratios of the from-scratch times.
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

from gaitopt.cli.study import parse_speeds
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve.staged import transcription_for
from gaitopt.robot import load_model
from gaitopt.study.driver import run_sweep
from gaitopt.study.executors import local_backend
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import VARIANTS
from gaitopt.study.worker import PointOutcome


def noop(x: int) -> int:
    import gaitopt.study.worker  # noqa: F401  (what a real worker imports)

    return os.getpid()


def pool_start_s(workers: int, method: str) -> float:
    """Time until every worker of a new pool has run a task (process start + imports)."""
    start = time.perf_counter()
    backend = local_backend(workers, start_method=method)
    futures = [backend.submit(noop, i) for i in range(workers * 4)]
    for f in futures:
        f.result()
    elapsed = time.perf_counter() - start
    backend.close()
    return elapsed


def build_s() -> float:
    """One transcription build (the no-ankle structure) in this process."""
    start = time.perf_counter()
    transcription_for(load_model("five-link"), GaitOptions.paper(ankle=False), (8, 5))
    return time.perf_counter() - start


def sweep_once(spec: SweepSpec, folder: Path, workers: int, method: str
               ) -> tuple[float, list[PointOutcome], int]:
    """One run of the sweep; the process pool is started only when there is work (as the
    command does), so a resumed run with nothing left starts none."""
    start = time.perf_counter()
    backend = local_backend(workers, start_method=method) if not folder.exists() else None
    try:
        report = run_sweep(spec, folder, backend=backend, workers=workers)
    finally:
        if backend is not None:
            backend.close()
    return time.perf_counter() - start, list(report.outcomes), report.counts.kept


def breakdown(outcomes: list[PointOutcome]) -> dict[str, float]:
    total: dict[str, float] = {}
    for o in outcomes:
        for k, v in o.timings.items():
            total[k] = total.get(k, 0.0) + v
    total["point_total_s"] = sum(o.wall_time_s for o in outcomes)
    return total


def builds(outcomes: list[PointOutcome]) -> int:
    """Transcriptions built: (worker, structure) pairs (a worker builds each at most once)."""
    seen: set[tuple[str, str]] = set()
    for o in outcomes:
        seen |= {(o.worker, s) for s in o.structures}
    return len(seen)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--speeds", default="3:60:3", help="m/min, as for gaitopt sweep")
    parser.add_argument("--free", action="store_true", help="also the speed-free optima")
    parser.add_argument("--start-methods", default="forkserver")
    parser.add_argument("--transcription", default="hermite-simpson-separated",
                        help="the sweep's transcription (GaitOptions.transcription)")
    parser.add_argument("--grid", choices=["paper", "default"], default="paper",
                        help="paper: GaitOptions.paper() (8+5 knots, the paper's control "
                             "model); default: GaitOptions() (16+6 knots, jumps), what "
                             "gaitopt sweep solves")
    parser.add_argument("--reference", default=None,
                        help="a git revision (e.g. main) to measure first in the same run, "
                             "with the paper's compressed form, as the reference of the ratios")
    parser.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    reference = run_reference(args) if args.reference else None

    spec = SweepSpec(model=load_model("five-link"), speeds=parse_speeds(args.speeds),
                     variants=VARIANTS, free_speed=args.free,
                     base=(GaitOptions.paper if args.grid == "paper" else GaitOptions)(
                         transcription=args.transcription))  # type: ignore[arg-type]
    n = len(spec.points)
    load = os.getloadavg()[0]
    print(f"sweep benchmark ({args.grid} grid, {spec.knots[0]}+{spec.knots[1]} knots, "
          f"{args.transcription}): {len(spec.variants)} variants x {len(spec.speeds)} speeds"
          f"{' + free' if args.free else ''} = {n} points, {args.workers} workers, "
          f"{os.cpu_count()} CPUs, load average before: {load:.2f}")
    ref_build = build_s()
    print(f"reference: one transcription build in this process: {ref_build:.2f} s")

    rows = []
    for method in args.start_methods.split(","):
        start_s = pool_start_s(args.workers, method)
        with tempfile.TemporaryDirectory(prefix="gaitopt-bench-sweep-") as tmp:
            folder = Path(tmp) / "sweep"
            cold, outcomes, _ = sweep_once(spec, folder, args.workers, method)
            resumed, again, kept = sweep_once(spec, folder, args.workers, method)
        ok = sum(o.success for o in outcomes)
        parts = breakdown(outcomes)
        warm = [o.timings.get("ipopt_s", 0.0) for o in outcomes if o.warm == "result"]
        fallbacks = sum(o.fell_back for o in outcomes)
        rows.append((method, cold, resumed, ok, len(again), kept))
        print(f"\n[{method}] pool start (processes + imports): {start_s:.2f} s")
        print(f"  from scratch: {cold:6.1f} s for {n} points ({ok} converged, "
              f"{fallbacks} warm starts fell back to cold), {60 * n / cold:.0f} solves/min; "
              f"target < 60 s: {'met' if cold < 60 else 'MISSED'}")
        print(f"  resumed:      {resumed:6.2f} s ({kept} kept, {len(again)} solved)")
        busy = parts["point_total_s"]
        nb = builds(outcomes)
        print(f"  where the time went (summed over points, {busy:.1f} s busy of "
              f"{args.workers} x {cold:.1f} = {args.workers * cold:.1f} worker-s, "
              f"{100 * busy / (args.workers * cold):.0f} % utilisation):")
        labels = {"build_and_setup_s": f"transcription builds ({nb}) and setup",
                  "ipopt_s": "IPOPT solves (all stages)", "record_s": "gait records",
                  "write_s": "gait file writes by the driver (atomic, fsync)",
                  "warm_start_s": "reading warm-start files"}
        for key, label in labels.items():
            value = parts.get(key, 0.0)
            print(f"    {label:<40} {value:7.2f} s  ({100 * value / busy:4.1f} %)")
        print(f"    {'estimate: builds x reference build':<40} {nb * ref_build:7.2f} s")
        if warm:
            print(f"  warm solves: {len(warm)}, median {statistics.median(warm):.3f} s, max "
                  f"{max(warm):.3f} s; cold starts: "
                  + ", ".join(f"{o.key.split('/')[1]} {o.wall_time_s:.1f} s"
                              for o in outcomes if o.warm == "none"))

    print("\n| start method | points | converged | from scratch (s) | solves/min | "
          "resumed (s) | solved on resume |")
    print("|---|---|---|---|---|---|---|")
    for method, cold, resumed, ok, again_n, _ in rows:
        print(f"| {method} | {n} | {ok} | {cold:.1f} | {60 * n / cold:.0f} | {resumed:.2f} | "
              f"{again_n} |")
    if reference is not None:
        print(f"\n| start method | reference {args.reference} (hermite-simpson), from scratch (s)"
              f" | this branch ({args.transcription}) (s) | this / reference | target (s) |")
        print("|---|---:|---:|---:|---:|")
        for method, cold, *_ in rows:
            ref = reference.get(method, float("nan"))
            print(f"| {method} | {ref:.1f} | {cold:.1f} | {cold / ref:.2f} | 8 |")
    if args.json:
        print(json.dumps({method: cold for method, cold, *_ in rows}))
    print(f"load average after: {os.getloadavg()[0]:.2f}")


def run_reference(args: argparse.Namespace) -> dict[str, float]:
    """This benchmark on git revision ``args.reference`` (its sources extracted into a
    temporary folder, the same interpreter), with the compressed form: the wall time from
    scratch by start method."""
    repo = Path(__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-ref-") as tmp:
        archive = subprocess.run(["git", "-C", str(repo), "archive", args.reference, "src"],
                                 check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        cmd = [sys.executable, str(Path(__file__).resolve()), "--workers", str(args.workers),
               "--speeds", args.speeds, "--start-methods", args.start_methods,
               "--transcription", "hermite-simpson", "--grid", args.grid,
               "--json"] + (["--free"] if args.free else [])
        print(f"reference: {args.reference} ({' '.join(cmd[2:])})", flush=True)
        proc = subprocess.run(cmd, env=dict(os.environ, PYTHONPATH=str(Path(tmp) / "src")),
                              capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"reference run failed:\n{proc.stderr[-3000:]}")
    print("\n".join("  | " + line for line in proc.stdout.splitlines()), flush=True)
    line = [t for t in proc.stdout.splitlines() if t.startswith("{")][-1]
    out: dict[str, float] = json.loads(line)
    return out


if __name__ == "__main__":
    main()
