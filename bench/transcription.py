"""Compressed against separated Hermite-Simpson on the walking problem, side by side.

For each grid (default 8 + 5 and 40 + 10 knots) and each form (``hermite-simpson``, DIRCOL's
compressed form, and ``hermite-simpson-separated``) on the default problem (five-link biped,
ankle torques and liftoff impulse, 12 m/min, step length free), every figure measured in
fresh worker processes of this run (so each starts with empty CasADi and NLP caches):

* ``cold``: the default staged solve (:func:`gaitopt.gait.solve.staged.solve_walking`) from the
  naive guess, NLP builds included: wall time, stages, IPOPT iterations, cost and step length;
* ``cold, exact fine``: the same with the target-grid stages solved with the exact Hessian
  instead of staged.py's limited-memory one (only for grids finer than 8 + 5);
* ``NLP build``: building the target grid's transcription (NLP assembly and SX expansion,
  no solver);
* ``first warm solve``: in a fresh process, the transcription built and solved from the
  ``cold`` solution at +5 % speed (12 -> 12.6 m/min) with the exact Hessian: the time a sweep
  worker pays for its first point, including the derivation of the exact Hessian;
* ``warm solve``: the same solve again in that process (best of ``--repeat``): wall time,
  iterations, ms per IPOPT iteration (IPOPT's total time / iterations) and the share of it
  spent in the NLP function evaluations (``Result.times``);
* the size of the exact Hessian function: SX instructions and nonzeros.

The last column is the ratio separated / compressed (< 1: the separated form is faster).

Run: ``python bench/transcription.py [--grids 8,5 40,10] [--repeat 3]``, or
``python bench/transcription.py --costs 8,5 16,6 40,10 80,20`` for the cold solves of both
forms on each grid only (cost J and step length: the two forms' optima agree on every grid).
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

FORMS = ("hermite-simpson", "hermite-simpson-separated")
SPEED = 0.2        # m/s, the paper's 12 m/min
SPEED_STEP = 1.05  # the neighbouring gait of the warm start


def _options(form: str, knots: tuple[int, int], speed: float = SPEED) -> Any:
    from gaitopt.gait.options.gait_options import GaitOptions

    return GaitOptions.paper(speed=speed, knots=knots, transcription=form)  # type: ignore[arg-type]


def worker_cold(form: str, knots: tuple[int, int], exact_fine: bool, out: str) -> dict[str, Any]:
    """A fresh process: the default cold solve; its Result is pickled to ``out``."""
    from gaitopt.gait.solve import staged as gait_solve
    from gaitopt.gait.solve import stages
    from gaitopt.robot import load_model

    if exact_fine:
        stages.FINE_STAGE_OPTIONS = {}
    model = load_model("five-link")
    start = time.perf_counter()
    sol = gait_solve.solve_walking(model, _options(form, knots))
    wall = time.perf_counter() - start
    if out:
        Path(out).write_bytes(pickle.dumps(sol.result))
    r = sol.result
    return {"wall": wall, "success": sol.success, "stages": len(sol.stages),
            "iterations": sum(s.iterations for s in sol.stages), "cost": r.objective,
            "step_length": r.parameters["step_length"], "errors": r.errors_by_phase(),
            "fine_iterations": sum(s.iterations for s in sol.stages if s.knots == knots)
            if knots != (8, 5) else None}


def worker_warm(form: str, knots: tuple[int, int], start_file: str,
                repeat: int) -> dict[str, Any]:
    """A fresh process: NLP build, first and repeated warm solves at +5 % speed."""
    from gaitopt.gait.solve.staged import PRIMAL_WARM_OPTIONS, solve_walking, transcription_for
    from gaitopt.ocp.solver import merge_options
    from gaitopt.robot import load_model

    model = load_model("five-link")
    start_result = pickle.loads(Path(start_file).read_bytes())
    options = _options(form, knots, SPEED * SPEED_STEP)
    t0 = time.perf_counter()
    tr = transcription_for(model, options, knots)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    first = solve_walking(model, options, warm_start=start_result)
    first_wall = time.perf_counter() - t0 + build
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        sol = solve_walking(model, options, warm_start=start_result)
        runs.append((time.perf_counter() - t0, sol))
    wall, sol = min(runs, key=lambda x: x[0])
    r = sol.result
    solver = tr.solver(merge_options(tr.options, PRIMAL_WARM_OPTIONS))
    hess = solver.get_function("nlp_hess_l")
    return {"build": build, "first_wall": first_wall, "first_ok": first.success,
            "wall": wall, "success": sol.success, "stages": len(sol.stages),
            "iterations": r.iterations,
            "ms_per_iteration": 1e3 * r.times["total"] / max(r.iterations, 1),
            "eval_share": r.times["evaluations"] / r.times["total"],
            "hess_share": r.times["nlp_hess_l"] / r.times["total"],
            "cost": r.objective, "variables": r.nlp_size.variables,
            "hess_instructions": hess.n_instructions(), "hess_nnz": hess.sparsity_out(0).nnz()}


def run_worker(args: list[str]) -> dict[str, Any]:
    """Run this file as a worker in a fresh interpreter; its last stdout line is JSON."""
    env = dict(os.environ)
    src = str(Path(__file__).resolve().parents[1] / "src")
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    proc = subprocess.run([sys.executable, __file__, "--worker", *args], env=env,
                          capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"worker {args} failed:\n{proc.stderr[-2000:]}")
    return dict(json.loads(proc.stdout.strip().splitlines()[-1]))


def load_average() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


ROWS: tuple[tuple[str, str, str, str], ...] = (
    # (label, measurement, key, format)
    ("cold solve, wall (s)", "cold", "wall", ".2f"),
    ("cold solve, IPOPT iterations", "cold", "iterations", "d"),
    ("cold solve, of which on the target grid", "cold", "fine_iterations", "d"),
    ("cold solve, cost J", "cold", "cost", ".6f"),
    ("cold solve, step length (m)", "cold", "step_length", ".6f"),
    ("cold, exact fine Hessian, wall (s)", "cold_exact", "wall", ".2f"),
    ("cold, exact fine Hessian, iterations on the target grid", "cold_exact",
     "fine_iterations", "d"),
    ("cold, exact fine Hessian, cost J", "cold_exact", "cost", ".6f"),
    ("NLP variables", "warm", "variables", "d"),
    ("NLP build, target grid (s)", "warm", "build", ".2f"),
    ("first warm solve in a fresh process, exact Hessian (s)", "warm", "first_wall", ".2f"),
    ("warm solve +5 % speed, wall (s)", "warm", "wall", ".3f"),
    ("warm solve, IPOPT iterations", "warm", "iterations", "d"),
    ("ms per IPOPT iteration", "warm", "ms_per_iteration", ".1f"),
    ("share of solve time in NLP evaluations", "warm", "eval_share", ".0%"),
    ("share of solve time in the Hessian", "warm", "hess_share", ".0%"),
    ("exact Hessian: SX instructions", "warm", "hess_instructions", ","),
    ("exact Hessian: nonzeros", "warm", "hess_nnz", ","),
)


def table(results: dict[tuple[str, tuple[int, int], str], dict[str, Any]],
          grids: list[tuple[int, int]]) -> str:
    lines = ["| grid | figure | compressed | separated | separated / compressed |",
             "|:---|:---|---:|---:|---:|"]
    for knots in grids:
        for label, what, key, fmt in ROWS:
            vals = [results.get((form, knots, what), {}).get(key) for form in FORMS]
            if any(v is None for v in vals):
                continue
            cells = [format(v, fmt) if fmt != "d" else str(int(v)) for v in vals]
            ratio = ""
            if isinstance(vals[0], int | float) and vals[0] and key not in ("cost",
                                                                           "step_length"):
                ratio = f"{vals[1] / vals[0]:.2f}"
            lines.append(f"| {knots[0]}+{knots[1]} | {label} | {cells[0]} | {cells[1]} | "
                         f"{ratio} |")
    return "\n".join(lines)


def cost_table(grids: list[str]) -> dict[tuple[str, tuple[int, int], str], Any]:
    """Cold solves of both forms on each grid (fresh processes): cost, step length and the
    largest interval error estimate of each phase (``Result.errors_by_phase``)."""
    results: dict[tuple[str, tuple[int, int], str], Any] = {}
    lines = ["| grid | form | converged | cost J | step length (m) | largest interval error "
             "by phase | IPOPT iterations | wall (s) |",
             "|:---|:---|:---|---:|---:|:---|---:|---:|"]
    for g in grids:
        knots = (int(g.split(",")[0]), int(g.split(",")[1]))
        for form in FORMS:
            r = run_worker(["cold", form, g])
            results[(form, knots, "cold")] = r
            line = (f"| {knots[0]}+{knots[1]} | {form} | {'yes' if r['success'] else 'NO'} | "
                    f"{r['cost']:.6f} | {r['step_length']:.6f} | "
                    f"{', '.join(f'{k} {v:.1e}' for k, v in r['errors'].items())} | "
                    f"{r['iterations']} | "
                    f"{r['wall']:.2f} |")
            print(line, flush=True)
            lines.append(line)
    print()
    print("\n".join(lines))
    print(f"\nload average after: {load_average()}")
    return results


def main(argv: list[str] | None = None) -> dict[tuple[str, tuple[int, int], str], Any]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grids", nargs="+", default=["8,5", "40,10"],
                        help="knots per phase, single,double")
    parser.add_argument("--repeat", type=int, default=3, help="best of N warm solves")
    parser.add_argument("--costs", nargs="+", metavar="GRID",
                        help="instead: only the cold solves of both forms on these grids, as a "
                             "table of cost and step length (e.g. 8,5 16,6 40,10 80,20)")
    parser.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        kind, form, grid, *rest = args.worker
        knots = (int(grid.split(",")[0]), int(grid.split(",")[1]))
        if kind in ("cold", "cold_exact"):
            out = worker_cold(form, knots, kind == "cold_exact", rest[0] if rest else "")
        else:
            out = worker_warm(form, knots, rest[0], int(rest[1]))
        print(json.dumps(out))
        return {}
    grids = [(int(g.split(",")[0]), int(g.split(",")[1])) for g in args.grids]
    print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores)")
    if args.costs:
        return cost_table(args.costs)
    results: dict[tuple[str, tuple[int, int], str], Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for knots in grids:
            g = f"{knots[0]},{knots[1]}"
            for form in FORMS:
                start = str(Path(tmp) / f"{form}-{knots[0]}-{knots[1]}.pkl")
                results[(form, knots, "cold")] = cold = run_worker(["cold", form, g, start])
                print(f"  {g} {form:<26} cold {cold['wall']:7.2f} s  it {cold['iterations']}"
                      f"  J {cold['cost']:.6f}  {'ok' if cold['success'] else 'FAILED'}",
                      flush=True)
                if knots != (8, 5):
                    results[(form, knots, "cold_exact")] = ce = run_worker(
                        ["cold_exact", form, g])
                    print(f"  {g} {form:<26} cold, exact fine {ce['wall']:7.2f} s  "
                          f"it {ce['iterations']}  J {ce['cost']:.6f}", flush=True)
                if not cold["success"]:
                    continue
                results[(form, knots, "warm")] = warm = run_worker(
                    ["warm", form, g, start, str(args.repeat)])
                print(f"  {g} {form:<26} build {warm['build']:.2f} s, first warm "
                      f"{warm['first_wall']:.2f} s, warm {warm['wall']:.3f} s "
                      f"({warm['iterations']} it, {warm['ms_per_iteration']:.1f} ms/it)",
                      flush=True)
    print()
    print(table(results, grids))
    print(f"\nload average after: {load_average()}")
    return results


if __name__ == "__main__":
    main()
