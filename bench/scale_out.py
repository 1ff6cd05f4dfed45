"""Scale-out on Dask (issue 27, item 5): a design study's sweep of seven-link heel-toe gaits
on a Dask ``LocalCluster`` with 1 and with 2 workers, against the same sweep in one process.

**The gaits.** A load-carriage design study: the ``seven-link`` heel-toe walk (the model's
defaults: full coordinates, 24 + 16 knots, ankle torques and the liftoff impulse, step length
free) carrying a payload on the torso (a mass added at the torso's centre of mass: 0, 5, 10,
15 and 20 kg by default) at speeds 34 to 112 m/min in steps of 2 (40 speeds): 5 bodies x 40
speeds = 200 gaits. Bodies x speeds is the shape of the 10,000-gait study the issue asks
about; payloads and speeds are what a designer varies, and 2 m/min steps are what a speed
sweep solves by continuation. The model's default grid is kept (each gait converges in about a
second there when warm-started from its neighbour): the point is the scale-out, measured on
the gaits a study would solve.

**The path.** Each body is one :class:`~gaitopt.study.plan.SweepSpec` run by
:func:`~gaitopt.study.driver.run_sweep`, the driver of ``gaitopt sweep``: with
``scheduler=ADDRESS`` (``gaitopt sweep --scheduler ADDRESS``,
:func:`~gaitopt.study.executors.dask_backend`) on the cluster, with ``workers=0``
(``--workers 0``, :func:`~gaitopt.study.executors.inline_backend`) in one process. A sweep's
points form continuation chains along the speed axis, up and down from the start speed
(72.2 m/min), so one body's sweep never keeps more than two workers busy; a study of many
bodies runs their sweeps at once, one driver (and one Dask client) per body against the same
scheduler, as several ``gaitopt sweep --scheduler`` commands would. The Dask runs do that
(one thread per body here); the in-process reference runs the bodies one after the other
(one core either way). Every chain starts from one seed gait file (the unloaded body at the
start speed, solved cold first: :func:`run_sweep`'s ``seeds``), so no run pays a cold start.

**The runs,** each in a fresh process of this script (``--child``), with BLAS and OpenMP
single-threaded, byte code written once and reused, in this order:

1. the seed: a cold solve of the unloaded body at the start speed (in this process);
2. compile: one body's first point with an empty function cache (``GAITOPT_CACHE`` in a
   temporary folder), then the same point again on the cache it filled: the difference is
   what a worker on a fresh machine pays once per body to derive the functions;
3. warm-up, unmeasured in the figures: each body's start point in one process, so the function
   cache on disk holds every body's compiled functions before the measured runs;
4. ``inline``: the sweep in one process (``--workers 0``);
5. ``dask-1``, ``dask-2``: the sweep on a ``LocalCluster(n_workers=W, threads_per_worker=1)``;
   the cluster's start (processes, and gaitopt imported in each worker) is timed apart from
   the sweep.

Printed: wall time, gaits per minute, the speed-up of 2 workers against 1, the per-gait
overhead of Dask against the in-process run ((sweep wall on 1 worker - in-process wall) / N),
the workers' peak RSS, and how many workers a 10,000-gait study needs for one hour.

    PYTHONPATH=src python bench/scale_out.py [--payloads 0,5,10,15,20] [--speeds 34:112:2]
        [--knots 24,16] [--runs inline,dask-1,dask-2] [--seed FILE] [--no-compile]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
MB = 2**20
#: The study whose worker count is asked for: gaits, and the wall time it may take (s).
STUDY_GAITS = 10_000
STUDY_HOURS = 1.0
SINGLE_THREADED = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
                   "MKL_NUM_THREADS": "1"}


# -- the gaits ----------------------------------------------------------------------------------

def bodies(payloads: list[float]) -> list[Any]:
    """``seven-link`` with each payload (kg) added to the torso at its centre of mass (the
    torso's inertia about its centre of mass is unchanged: a point mass there)."""
    from gaitopt.robot import load_model

    model = load_model("seven-link")
    out = []
    for kg in payloads:
        links = tuple(replace(link, mass=link.mass + kg) if link.parent is None else link
                      for link in model.links)
        out.append(replace(model, name=f"seven-link-payload-{kg:g}kg", links=links))
    return out


def specs(args: argparse.Namespace) -> list[Any]:
    """One sweep per body: the ankle+impulse variant, the speeds, no speed-free point."""
    from gaitopt.cli.study import parse_speeds
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.study.plan import SweepSpec

    base = GaitOptions(gait="heel-toe")
    if args.knots:
        base = base.replace(knots=tuple(int(k) for k in args.knots.split(",")))
    speeds = tuple(parse_speeds(args.speeds))
    return [SweepSpec(model=m, speeds=speeds, variants=("ankle+impulse",), free_speed=False,
                      base=base) for m in bodies(args.payload_list)]


def start_key(spec: Any) -> str:
    """The key of the point each chain of ``spec`` starts from (nearest the start speed)."""
    from gaitopt.study.plan import start_index

    fixed = [p for p in spec.points if p.speed is not None]
    return str(fixed[start_index([p.speed for p in fixed], spec.start)].key)


def solve_seed(spec: Any, path: Path) -> float:
    """The unloaded body's gait at the start speed, solved cold (staged, one grid); its
    wall time (s)."""
    from gaitopt.gait.api import solve_staged_run
    from gaitopt.gait.solve.record import gait_from_run

    point = next(p for p in spec.points if p.key == start_key(spec))
    start = time.perf_counter()
    run = solve_staged_run(spec.model_of(point), spec.options(point).replace(speed=spec.start),
                           refine=False)
    if not run.success:
        raise SystemExit(f"the seed's cold solve failed: {run.result.status}")
    gait_from_run(run).save(path)
    return time.perf_counter() - start


# -- one run (in a child process) -------------------------------------------------------------

def outcome_rows(reports: list[Any]) -> list[dict[str, Any]]:
    return [{"key": o.key, "success": o.success, "warm": o.warm, "iterations": o.iterations,
             "wall_s": o.wall_time_s, "worker": o.worker,
             "build_s": o.timings.get("build_and_setup_s", 0.0)}
            for report in reports for o in report.outcomes]


def run_inline(all_specs: list[Any], seed: str, out: Path) -> dict[str, Any]:
    from gaitopt.process_memory import peak_resident_bytes
    from gaitopt.study.driver import run_sweep

    start = time.perf_counter()
    reports = [run_sweep(spec, out / f"body-{i}", workers=0, seeds={start_key(spec): seed})
               for i, spec in enumerate(all_specs)]
    wall = time.perf_counter() - start
    return {"wall_s": wall, "startup_s": 0.0, "points": outcome_rows(reports),
            "peak_rss_mb": [peak_resident_bytes() / MB]}


def _import_worker() -> int:
    import gaitopt.study.worker  # noqa: F401  (what the first task would import)

    return os.getpid()


def _peak_rss() -> int:
    from gaitopt.process_memory import peak_resident_bytes

    return peak_resident_bytes()


def run_dask(all_specs: list[Any], seed: str, out: Path, workers: int) -> dict[str, Any]:
    from distributed import Client, LocalCluster

    from gaitopt.process_memory import peak_resident_bytes
    from gaitopt.study.driver import run_sweep

    start = time.perf_counter()
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None, local_directory=str(out / "dask")) as cluster, \
            Client(cluster) as client:
        client.wait_for_workers(workers)
        client.run(_import_worker)
        startup = time.perf_counter() - start
        address = cluster.scheduler_address

        def one(i: int) -> Any:
            spec = all_specs[i]
            return run_sweep(spec, out / f"body-{i}", scheduler=address,
                             seeds={start_key(spec): seed})

        mark = time.perf_counter()
        with ThreadPoolExecutor(max_workers=len(all_specs)) as pool:
            reports = list(pool.map(one, range(len(all_specs))))
        wall = time.perf_counter() - mark
        rss = [v / MB for v in client.run(_peak_rss).values()]
    return {"wall_s": wall, "startup_s": startup, "points": outcome_rows(reports),
            "peak_rss_mb": rss, "driver_peak_rss_mb": peak_resident_bytes() / MB}


def child(args: argparse.Namespace) -> None:
    """One run in this process; one JSON line of figures on stdout."""
    all_specs = specs(args)
    if args.child == "warmup":  # each body's start point: the disk cache holds every body
        all_specs = [replace(s, speeds=(s.start,)) for s in all_specs]
    if args.child == "compile":
        all_specs = [replace(all_specs[-1], speeds=(all_specs[-1].start,))]
    with tempfile.TemporaryDirectory(prefix="gaitopt-scale-") as tmp:
        out = Path(tmp)
        if args.child.startswith("dask-"):
            figures = run_dask(all_specs, args.seed, out, int(args.child.split("-")[1]))
        else:
            figures = run_inline(all_specs, args.seed, out)
    print(json.dumps({"run": args.child, "load": os.getloadavg()[0],
                      "bodies": args.payload_list, **figures}))


def spawn(run: str, args: argparse.Namespace, env: dict[str, str]) -> dict[str, Any]:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", run, "--seed", args.seed,
           "--payloads", args.payloads, "--speeds", args.speeds]
    if args.knots:
        cmd += ["--knots", args.knots]
    load = os.getloadavg()[0]
    print(f"[{time.strftime('%H:%M:%S', time.gmtime())} UTC] {run} (load {load:.2f}) ...",
          flush=True)
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    lines = [t for t in proc.stdout.splitlines() if t.startswith("{")]
    if proc.returncode != 0 or not lines:
        raise SystemExit(f"{run} failed:\n{proc.stderr[-4000:]}")
    out: dict[str, Any] = json.loads(lines[-1])
    out["load_before"] = load
    return out


# -- the report ---------------------------------------------------------------------------------

def summary(fig: dict[str, Any]) -> dict[str, Any]:
    """A run's figures: wall and busy (summed point) times, per gait, the seeded starts and
    warm points apart, the time no worker was solving."""
    points = fig["points"]
    n = len(points)
    busy = sum(p["wall_s"] for p in points)
    workers = len({p["worker"] for p in points})
    starts = [p["wall_s"] for p in points if p["warm"] != "result"]
    warm = sorted(p["wall_s"] for p in points if p["warm"] == "result")
    return {"n": n, "ok": sum(p["success"] for p in points), "wall": fig["wall_s"],
            "busy": busy, "per_gait": fig["wall_s"] / n, "busy_per_gait": busy / n,
            "gpm": 60 * n / fig["wall_s"], "startup": fig["startup_s"],
            "iterations": sum(p["iterations"] for p in points),
            "rss": fig["peak_rss_mb"], "workers": workers,
            "idle_per_gait": (workers * fig["wall_s"] - busy) / n,
            "starts": starts, "warm_median": warm[len(warm) // 2] if warm else math.nan,
            "warm_mean": sum(warm) / len(warm) if warm else math.nan,
            "build": sum(p["build_s"] for p in points), "bodies": len(fig["bodies"])}


def workers_needed(per_gait_s: float, efficiency: float) -> int:
    """Workers for :data:`STUDY_GAITS` gaits in :data:`STUDY_HOURS` hours, at ``per_gait_s``
    of one worker per gait and ``efficiency`` (speed-up per worker)."""
    return math.ceil(STUDY_GAITS * per_gait_s / (3600 * STUDY_HOURS * efficiency))


def report(runs: dict[str, dict[str, Any]], seed_s: float | None,
           compile_fig: dict[str, Any] | None, recompile_fig: dict[str, Any] | None) -> None:
    sums = {name: summary(fig) for name, fig in runs.items()}
    print("\n| run | gaits (converged) | workers | cluster start s | sweep wall s | "
          "gaits/min | wall s/gait | busy s/gait | idle s/gait | IPOPT iterations | "
          "peak RSS MB | load |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for name, s in sums.items():
        rss = ", ".join(f"{v:.0f}" for v in s["rss"])
        print(f"| {name} | {s['n']} ({s['ok']}) | {s['workers']} | {s['startup']:.1f} | "
              f"{s['wall']:.1f} | {s['gpm']:.1f} | {s['per_gait']:.3f} | "
              f"{s['busy_per_gait']:.3f} | {s['idle_per_gait']:.3f} | {s['iterations']} | "
              f"{rss} | {runs[name]['load_before']:.2f} |")
    print("(busy: the points' own wall times summed, in the worker; idle: workers x wall - "
          "busy, per gait: the time a worker was not solving; peak RSS of each worker "
          "process, or of the one process)")
    for name, s in sums.items():
        starts = ", ".join(f"{v:.1f}" for v in s["starts"])
        driver = runs[name].get("driver_peak_rss_mb")
        print(f"  {name}: seeded starts {starts} s; warm points median {s['warm_median']:.2f} "
              f"s, mean {s['warm_mean']:.2f} s; builds and setup {s['build']:.1f} s in all"
              + (f"; the driver process's peak RSS {driver:.0f} MB" if driver else ""))
    if seed_s is not None:
        print(f"seed (cold solve of the unloaded body at the start speed, one grid): "
              f"{seed_s:.1f} s")
    compile_s = None
    if compile_fig is not None and recompile_fig is not None:
        # The derivation is timed as the difference of two solves of one point: the body's
        # first point with an empty function cache, then again on the cache that solve
        # filled (the same seed, the same iterations). The stages build their solvers, so a
        # point's build_s does not hold the derivation.
        first = compile_fig["points"][0]
        same = [p["wall_s"] for p in recompile_fig["points"]
                if p["key"] == first["key"] and p["iterations"] == first["iterations"]]
        if same:
            compile_s = max(0.0, first["wall_s"] - min(same))
            print(f"a body's first point: {first['wall_s']:.1f} s with an empty function "
                  f"cache, {min(same):.1f} s from the cache on disk ({first['iterations']} "
                  f"iterations both): deriving the functions {compile_s:.1f} s")
    def best(config: str) -> dict[str, Any] | None:  # the fastest of a config's repeats
        mine = [v for k, v in sums.items() if k.split("#")[0] == config]
        return min(mine, key=lambda v: v["wall"]) if mine else None

    one, two, ref = best("dask-1"), best("dask-2"), best("inline")
    if len(sums) > 3:
        print("\nthe figures below take each run's fastest repeat")
    speedup = one["wall"] / two["wall"] if one and two else math.nan
    if one and two:
        print(f"\nspeed-up, 2 workers against 1: {speedup:.2f} (efficiency "
              f"{speedup / 2:.2f} per worker)")
    if one and ref:
        over = (one["wall"] - ref["wall"]) / one["n"]
        idle = one["idle_per_gait"] - ref["idle_per_gait"]
        print(f"per-gait overhead of Dask (1 worker) against the in-process run: "
              f"{over:+.3f} s/gait from the walls ({100 * over / ref['per_gait']:+.1f} %), "
              f"{idle:+.3f} s/gait from the time outside the solves (idle); the solves "
              f"themselves {one['busy_per_gait']:.3f} against {ref['busy_per_gait']:.3f} s/gait")
    if one and two:
        eff = min(1.0, speedup / 2)
        need = workers_needed(one["per_gait"], eff)
        print(f"\n{STUDY_GAITS:,}-gait study in {STUDY_HOURS:g} h: {need} workers "
              f"(one core each), from {one['per_gait']:.3f} s per gait on one Dask worker "
              f"(this sweep's mix: {one['n']} gaits, one seeded start per body, the rest "
              f"warm from a neighbour) and {eff:.2f} of linear scaling per worker as measured "
              f"from 1 to 2 workers: {STUDY_GAITS:,} x {one['per_gait']:.3f} s / (3600 s x "
              f"{eff:.2f})")
        if compile_s is not None:
            bodies_n = STUDY_GAITS * one["bodies"] // one["n"]
            extra = bodies_n * compile_s
            with_compile = workers_needed((STUDY_GAITS * one["per_gait"] + extra)
                                          / STUDY_GAITS, eff)
            print(f"  with the functions compiled on the cluster ({bodies_n} bodies of "
                  f"{one['n'] // one['bodies']} speeds, {compile_s:.1f} s each, once per body: "
                  f"a function cache the workers share, GAITOPT_CACHE): {with_compile} workers; "
                  f"a worker without that cache compiles every body it meets again "
                  f"(all {bodies_n}: {extra / 3600:.1f} h)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--payloads", default="0,5,10,15,20", help="kg on the torso, a body each")
    parser.add_argument("--speeds", default="34:112:2", help="m/min, as for gaitopt sweep")
    parser.add_argument("--knots", default="", help="the grid (default: the model's, 24,16)")
    parser.add_argument("--runs", default="inline,dask-1,dask-2")
    parser.add_argument("--repeat", type=int, default=1, help="run the --runs this many "
                        "times, in turn (the figures take each run's fastest)")
    parser.add_argument("--seed", default="", help="a seed gait file to reuse (default: "
                                                   "solved cold first)")
    parser.add_argument("--no-compile", action="store_true",
                        help="skip the first point with an empty function cache")
    parser.add_argument("--json", default="", help="also write every figure to this file")
    parser.add_argument("--from-json", default="", help="print the report of a --json file")
    parser.add_argument("--child", default="", help=argparse.SUPPRESS)
    args = parser.parse_args()
    args.payload_list = [float(x) for x in args.payloads.split(",")]
    for key, value in SINGLE_THREADED.items():  # before numpy loads
        os.environ.setdefault(key, value)
    if args.child:
        child(args)
        return
    if args.from_json:
        saved = json.loads(Path(args.from_json).read_text())
        report(saved["runs"], saved["seed_s"], saved["compile"], saved.get("recompile"))
        return

    from gaitopt import __version__

    all_specs = specs(args)
    n = sum(len(s.points) for s in all_specs)
    print(f"scale-out: seven-link heel-toe, {len(all_specs)} bodies (payload "
          f"{args.payloads} kg) x {len(all_specs[0].speeds)} speeds ({args.speeds} m/min) = "
          f"{n} gaits, {all_specs[0].knots[0]}+{all_specs[0].knots[1]} knots; gaitopt "
          f"{__version__}, {os.cpu_count()} CPUs, load {os.getloadavg()}")
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-scale-") as tmp:
        env = dict(os.environ, PYTHONPATH=str(REPO / "src"), **SINGLE_THREADED)
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(Path(tmp) / "bytecode")
        seed_s = None
        if not args.seed:
            args.seed = str(Path(tmp) / "seed.gait.json")
            seed_s = solve_seed(all_specs[0], Path(args.seed))
            print(f"seed solved cold in {seed_s:.1f} s", flush=True)
        compile_fig = recompile_fig = None
        if not args.no_compile:  # the same point twice on one new cache: empty, then warm
            fresh = dict(env, GAITOPT_CACHE=str(Path(tmp) / "fc"))
            compile_fig = spawn("compile", args, fresh)
            recompile_fig = spawn("compile", args, fresh)
        warm_fig = spawn("warmup", args, env)
        runs = {f"{run}#{r + 1}" if args.repeat > 1 else run: spawn(run, args, env)
                for r in range(args.repeat) for run in args.runs.split(",")}
    report(runs, seed_s, compile_fig, recompile_fig)
    print(f"load average after: {os.getloadavg()}")
    if args.json:
        Path(args.json).write_text(json.dumps({"runs": runs, "seed_s": seed_s,
                                               "compile": compile_fig, "warmup": warm_fig,
                                               "recompile": recompile_fig}))


if __name__ == "__main__":
    main()
