"""Benchmark of the walking solve against the paper's DIRCOL figures and the issue's targets.

In one run, at the paper's grid (8 + 5 knots) and at a fine grid (40 + 10 knots), for the
default problem (12 m/min, ankle torques and liftoff impulse, step length free):

* ``cold (fresh)``: the default solve from the naive guess with the automatic continuation,
  the process-wide NLP cache emptied first, so NLP construction (CasADi graphs, derivatives,
  IPOPT instance) is included;
* ``cold (cache built)``: the same solve again, the NLPs already built; the difference of the
  two is the build time;
* ``warm (same speed)``: the target problem solved from the converged solution's Result, its
  multipliers passed to IPOPT;
* ``warm (speed +5 %)``: the same after a small speed change (12 -> 12.6 m/min);
* ``file (speed +5 %)``: the same through the public API from the saved gait (its NLP point
  and multipliers, ``solver.warm_start``), as ``gaitopt solve --warm-start`` does.

``--formulation full`` measures the full-coordinate formulation instead.

Per solve: wall time, stages, IPOPT iterations and function evaluations by kind summed over
the stages, time inside the evaluations, and the "state equation calls" counted as DIRCOL
counts them: every evaluation of the constraints ``g`` evaluates the dynamics once at every
knot and every collocation midpoint (Hermite-Simpson), so calls = (knots + midpoints) x nlp_g
per stage. Derivatives are by automatic differentiation here (DIRCOL used finite differences,
which is where most of its state-equation calls went); the ``incl. AD sweeps`` column also
counts one dynamics sweep per Jacobian and Hessian evaluation, as a generous upper figure.

The paper's table (Sparc Ultra 2, 166 MHz): DIRCOL 1.2 / NPSOL 568,635 state-equation calls in
18 min; DIRCOL 2.0 / SNOPT 230,952 calls in 12 min (one sample run, 8 + 5 grid). The targets
on this machine: warm solve under 0.25 s at 8 + 5 and under 1.5 s at 40 + 10; cold under 10 s.

Timings on a shared machine are noisy: the load average is printed before and after, and
``--repeat N`` keeps the best of N for the warm and cached-cold solves.

``--targets`` prints only the rows of the issue's table (warm starts from a saved gait file at
8 + 5 and 40 + 10 knots, the first one in a fresh process, whole ``gaitopt solve``
processes, the share of the solve spent in NLP evaluations), and a whole ``gaitopt solve``
with each revision's own defaults (what a user gets), for this branch's fast path
(separated Hermite-Simpson, derivatives from compiled point functions) and for a reference
git revision (``--reference``, default ``main``: its sources extracted into a temporary
folder and run by the same interpreter, on the paper's compressed form, main's default),
each row measured for both one after the other in fresh processes (``bench/gait_child.py``),
with the ratios; ``--reference-transcription hermite-simpson-separated`` runs the reference in
this branch's form instead, so that the ratios isolate the branch's changes.

Run: ``python bench/gait.py [--repeat 3] [--grids 8,5 40,10] [--formulation full]
[--transcription hermite-simpson-separated]`` or ``python bench/gait.py --targets``
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.record import gait_from_run
from gaitopt.gait.solve.staged import StagedRun, solve_walking
from gaitopt.gait.solve.transcriptions import clear_cache
from gaitopt.ocp import Result
from gaitopt.ocp.result import METHODS
from gaitopt.ocp.transcription import Transcription
from gaitopt.robot import load_model

PAPER = (("DIRCOL 1.2 / NPSOL", 18 * 60.0, 568_635),
         ("DIRCOL 2.0 / SNOPT", 12 * 60.0, 230_952))
TARGETS = {("warm", (8, 5)): 0.25, ("warm", (40, 10)): 1.5, ("cold", (8, 5)): 10.0,
           ("cold", (40, 10)): 10.0}
KINDS = ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l")
NOTE = ("State-equation calls: each evaluation of g evaluates the dynamics once at every knot "
        "and every Hermite-Simpson midpoint, so calls = (knots + midpoints) x nlp_g, summed over "
        "the stages; 'incl. AD sweeps' adds one sweep per nlp_jac_g and nlp_hess_l call (DIRCOL "
        "differentiated by finite differences, gaitopt by AD). Targets: warm < 0.25 s (8+5), "
        "< 1.5 s (40+10); cold < 10 s.")
SPEED = 0.2        # m/s, the paper's 12 m/min
SPEED_STEP = 1.05  # the "small speed change"


@dataclass
class Measure:
    """One measured solve (figures summed over its stages)."""

    name: str
    knots: tuple[int, int]
    wall_s: float
    success: bool
    stages: int = 0
    iterations: int = 0
    evaluations: dict[str, int] = field(default_factory=dict)
    eval_time_s: float = 0.0
    state_calls: int = 0
    state_calls_ad: int = 0
    cost: float = float("nan")


def points_per_g(result: Result) -> int:
    """Dynamics evaluations in one evaluation of g: knots, plus midpoints for
    Hermite-Simpson (either form)."""
    mid = METHODS[result.method].needs_midpoint_dynamics
    total = 0
    for ph in result.phases:
        k = ph.t.size
        total += k + (k - 1 if mid else 0)
    return total


@contextlib.contextmanager
def recording() -> Iterator[list[Result]]:
    """Collect every Result the engine returns while the block runs (all stages)."""
    results: list[Result] = []
    original = Transcription.solve

    def solve(self: Transcription, *args: Any, **kwargs: Any) -> Result:
        result = original(self, *args, **kwargs)
        results.append(result)
        return result

    Transcription.solve = solve  # type: ignore[method-assign]
    try:
        yield results
    finally:
        Transcription.solve = original  # type: ignore[method-assign]


def measure(name: str, knots: tuple[int, int], run: Callable[[], StagedRun]
            ) -> tuple[Measure, StagedRun]:
    with recording() as results:
        start = time.perf_counter()
        solution = run()
        wall = time.perf_counter() - start
    m = Measure(name, knots, wall, solution.success, stages=len(results),
                cost=solution.result.objective)
    m.evaluations = {k: sum(r.evaluations.get(k, 0) for r in results) for k in KINDS}
    m.iterations = sum(r.iterations for r in results)
    m.eval_time_s = sum(r.times.get("evaluations", 0.0) for r in results)
    for r in results:
        n = points_per_g(r)
        m.state_calls += n * r.evaluations.get("nlp_g", 0)
        m.state_calls_ad += n * sum(r.evaluations.get(k, 0)
                                    for k in ("nlp_g", "nlp_jac_g", "nlp_hess_l"))
    return m, solution


def best_of(repeat: int, name: str, knots: tuple[int, int],
            run: Callable[[], StagedRun]) -> tuple[Measure, StagedRun]:
    runs = [measure(name, knots, run) for _ in range(repeat)]
    return min(runs, key=lambda mr: mr[0].wall_s)


def bench_grid(knots: tuple[int, int], repeat: int, formulation: str = "reduced",
               transcription: str = "hermite-simpson") -> list[Measure]:
    model = load_model("five-link")
    options = GaitOptions.paper(speed=SPEED, knots=knots, formulation=formulation,  # type: ignore
                                transcription=transcription)  # type: ignore[arg-type]
    clear_cache()  # the process-wide NLP cache: a fresh start
    fresh, _ = measure("cold (fresh)", knots, lambda: solve_walking(model, options))
    cached, solution = best_of(repeat, "cold (cache built)", knots,
                               lambda: solve_walking(model, options))
    if not solution.success:
        return [fresh, cached]
    start = solution.result
    same, _ = best_of(repeat, "warm (same speed)", knots,
                      lambda: solve_walking(model, options, warm_start=start))
    faster = options.replace(speed=SPEED * SPEED_STEP)
    moved, _ = best_of(repeat, f"warm (speed +{(SPEED_STEP - 1) * 100:.0f} %)", knots,
                       lambda: solve_walking(model, faster, warm_start=start))
    # The public path from a saved gait: the file's NLP point and multipliers (WarmStart).
    saved = Gait.from_dict(gait_from_run(solution).to_dict())
    from_file, _ = best_of(repeat, f"file (speed +{(SPEED_STEP - 1) * 100:.0f} %)", knots,
                           lambda: solve_staged_run(model, faster, warm_start=saved))
    return [fresh, cached, same, moved, from_file]


def load_average() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def table(measures: list[Measure]) -> str:
    rows = ["| grid | solve | ok | wall (s) | target (s) | wall / target | stages | "
            "iterations | nlp_f | nlp_g | nlp_grad_f | nlp_jac_g | nlp_hess_l | "
            "in evaluations (s) | state-equation calls | incl. AD sweeps | cost |",
            "|:---|:---|:---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
            "---:|"]
    for m in measures:
        target = TARGETS.get(("warm" if m.name.startswith("warm") else "cold", m.knots))
        ratio = f"{m.wall_s / target:.2f}" if target else ""
        ev = " | ".join(f"{m.evaluations.get(k, 0):,}" for k in KINDS)
        rows.append(f"| {m.knots[0]}+{m.knots[1]} | {m.name} | {'yes' if m.success else 'NO'} "
                    f"| {m.wall_s:.3f} | {target:g} | {ratio} | {m.stages} | {m.iterations} | "
                    f"{ev} | {m.eval_time_s:.3f} | {m.state_calls:,} | {m.state_calls_ad:,} | "
                    f"{m.cost:.4f} |")
    for name, wall, calls in PAPER:
        rows.append(f"| 8+5 | paper: {name} | yes | {wall:.0f} | | | | | | | | | | | "
                    f"{calls:,} | | |")
    return "\n".join(rows)


# -- the issue's targets, against a reference revision measured in the same run ------------

#: The issue's targets (s; the share as a fraction), by row.
ISSUE_TARGETS = {"warm 8+5": 0.05, "warm 40+10": 0.15, "first warm 40+10": 0.5,
                 "cli 8+5": 1.0, "cli 40+10": 2.0, "share 8+5": 0.5, "share 40+10": 0.5}
#: The transcription measured on this branch (the reference runs the paper's compressed form,
#: main's default, evaluated as main evaluates it).
FAST = "hermite-simpson-separated"
PAPER_FORM = "hermite-simpson"
REPO = Path(__file__).resolve().parent.parent


def reference_sources(rev: str, into: Path) -> Path:
    """The ``src`` folder of git revision ``rev`` of this repository, extracted into
    ``into`` (the same interpreter and packages run it)."""
    archive = subprocess.run(["git", "-C", str(REPO), "archive", rev, "src"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return into / "src"


#: With ``--bytecode``: the folder where the child processes keep the byte code of the sources
#: they import (``PYTHONPYCACHEPREFIX``), as an installed package keeps its ``.pyc`` files.
BYTECODE: dict[str, Path] = {}


def child_env(src: Path) -> dict[str, str]:
    """The environment of a measured process: ``src`` first on the path; with ``--bytecode``
    byte code written and reused (``PYTHONDONTWRITEBYTECODE``, which this machine sets, makes
    every process compile every imported source again: about 0.1 s of CPU per process)."""
    env = dict(os.environ, PYTHONPATH=str(src))
    if "dir" in BYTECODE:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(BYTECODE["dir"])
    return env


def run_child(src: Path, *args: str) -> tuple[dict[str, Any], float]:
    """``bench/gait_child.py args`` in a fresh process with ``src`` first on the path: its
    JSON output and the wall time of the whole process."""
    env = child_env(src)
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, str(REPO / "bench" / "gait_child.py"), *args],
                          env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"gait_child {' '.join(args)} failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1]), wall


def uniform_knots(src: Path) -> list[str]:
    """``--knot-spacing uniform`` where the revision at ``src`` has the option: the issue's
    8 + 5 and 40 + 10 rows are uniform grids (cosine knots became the default without the
    option, so a revision between the two solves the cosine grid and checks it on a finer
    one)."""
    cli = src / "gaitopt" / "cli" / "gait.py"
    return ["--knot-spacing", "uniform"] if "knot_spacing_option" in cli.read_text() else []


def run_cli(src: Path, transcription: str | None, knots: str | None, out: Path,
            formulation: str = "reduced") -> tuple[float, float]:
    """Wall and CPU time (user + system) of a whole ``gaitopt solve`` process (12 m/min):
    on ``knots`` with the paper's control model in ``transcription``, or with ``knots``
    None the command's own defaults (``gaitopt solve -o FILE``, what a user gets)."""
    env = child_env(src)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    chosen = ([] if knots is None else
              ["--speed", "12m/min", "--knots", knots, "--control-model", "paper",
               *uniform_knots(src),
               "--transcription", str(transcription), "--formulation", formulation])
    proc = subprocess.run([sys.executable, "-m", "gaitopt", "solve", *chosen, "-o", str(out)],
                          env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"gaitopt solve failed:\n{proc.stderr[-3000:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def targets(reference: str, repeat: int, formulation: str = "reduced",
            reference_form: str = PAPER_FORM) -> None:
    """Every row of the issue's table for the reference revision (by default the paper's
    compressed form, as main solved it by default; ``reference_form`` another transcription,
    e.g. :data:`FAST` to isolate this branch's changes) and this branch (:data:`FAST`), each
    row measured for both one after the other, and the ratios."""
    here = REPO / "src"
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-") as tmp_name:
        tmp = Path(tmp_name)
        ref = reference_sources(reference, tmp)
        variants = (("reference", ref, reference_form), ("this branch", here, FAST))
        rows: dict[str, dict[str, float]] = {}
        cpu: dict[str, dict[str, float]] = {}
        notes: list[str] = []

        def record(row: str, name: str, value: float, cpu_s: float | None = None) -> None:
            rows.setdefault(row, {})[name] = value
            if cpu_s is not None:
                cpu.setdefault(row, {})[name] = cpu_s

        for knots in ("8,5", "40,10"):
            grid = knots.replace(",", "+")
            for name, src, form in variants:
                gait_file = tmp / f"{name.replace(' ', '_')}-{grid}.gait.json"
                out, _ = run_child(src, "warm", knots, form, str(repeat), str(gait_file),
                                   formulation)
                record(f"warm {grid}", name, out["warm_s"], out["warm_cpu_s"])
                record(f"share {grid}", name, out["cold_eval_s"] / max(out["cold_ipopt_s"],
                                                                       1e-12))
                notes.append(f"{name} {grid}: cold {out['cold_first_s']:.2f} s (NLPs built), "
                             f"{out['cold_cached_s']:.2f} s again ({out['cold_iterations']} it,"
                             f" J {out['cost']:.4f}); warm from the file {out['warm_s']:.3f} s "
                             f"({out['warm_iterations']} it, J {out['warm_cost']:.4f}, "
                             f"{out['warm_eval_s'] / max(out['warm_ipopt_s'], 1e-12):.0%} in "
                             f"evaluations)")
                print(notes[-1], flush=True)
                if grid == "40+10":
                    first, proc = run_child(src, "first-warm", knots, form, str(gait_file),
                                            formulation)
                    record("first warm 40+10", name, first["first_warm_s"],
                           first["first_warm_cpu_s"])
                    notes.append(f"{name} 40+10 fresh process: first warm start "
                                 f"{first['first_warm_s']:.2f} s ({first['iterations']} it), "
                                 f"imports {first['imports_s']:.2f} s, whole process "
                                 f"{proc:.2f} s")
                    print(notes[-1], flush=True)
        for knots in ("8,5", "40,10"):
            grid = knots.replace(",", "+")
            for name, src, form in variants:
                runs = [run_cli(src, form, knots, tmp / "cli.gait.json", formulation)
                        for _ in range(1 + repeat)]
                best_run = min(runs[1:])
                record(f"cli {grid}", name, best_run[0], best_run[1])
                notes.append(f"{name} gaitopt solve --knots {knots}: "
                             + ", ".join(f"{r[0]:.2f} ({r[1]:.2f} CPU)" for r in runs)
                             + " s (first run, then with the disk caches warm; best of the "
                               "latter)")
                print(notes[-1], flush=True)
        if formulation == "reduced":
            # What a user gets: `gaitopt solve` with every default (each revision's own).
            for name, src, _ in variants:
                runs = [run_cli(src, None, None, tmp / "cli.gait.json")
                        for _ in range(1 + repeat)]
                best_run = min(runs[1:])
                record("cli default", name, best_run[0], best_run[1])
                notes.append(f"{name} gaitopt solve (its defaults): "
                             + ", ".join(f"{r[0]:.2f} ({r[1]:.2f} CPU)" for r in runs)
                             + " s (first run, then best of the others)")
                print(notes[-1], flush=True)
    labels = {
        "warm 8+5": "warm start from a saved gait, +5 % speed, 8+5 knots (public API), s",
        "warm 40+10": "the same, 40+10 knots, s",
        "first warm 40+10": "the first such warm start at 40+10 in a fresh process, s",
        "cli 8+5": "cold `gaitopt solve`, whole process, 8+5 knots (disk caches warm), s",
        "cli 40+10": "cold `gaitopt solve --knots 40,10`, whole process, s",
        "cli default": "cold `gaitopt solve` with each revision's defaults (16+6 knots), "
                       "whole process, s",
        "share 8+5": "share of the cold solve's IPOPT time in NLP evaluations, 8+5",
        "share 40+10": "the same, 40+10",
    }
    print()
    print(f"formulation: {formulation}")
    print(f"| figure | reference ({reference}, {reference_form}) | this branch ({FAST}) | "
          "this / reference | target | met | CPU s: reference, this branch |")
    print("| --- | ---: | ---: | ---: | ---: | :---: | ---: |")
    for row, label in labels.items():
        if row not in rows:
            continue
        r, b = rows[row]["reference"], rows[row]["this branch"]
        fmt = "{:.0%}" if row.startswith("share") else "{:.3f}"
        target = ISSUE_TARGETS.get(row)
        c = cpu.get(row)
        cpu_text = f"{c['reference']:.3f}, {c['this branch']:.3f}" if c else ""
        met = "" if target is None else ("yes" if b <= target else "no")
        print(f"| {label} | {fmt.format(r)} | {fmt.format(b)} | {b / r:.2f} | "
              f"{'' if target is None else fmt.format(target)} | {met} | {cpu_text} |")
    print("| 80-point sweep, 2 workers | see `bench/sweep.py --reference` | | | 8 | |")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3,
                        help="best of N for the cached-cold and warm solves")
    parser.add_argument("--grids", nargs="+", default=["8,5", "40,10"],
                        help="knots per phase, single,double")
    parser.add_argument("--formulation", choices=["reduced", "full"], default="reduced",
                        help="the walking problem's coordinates (docs/formulations.md)")
    parser.add_argument("--transcription", default=PAPER_FORM,
                        help="the transcription of the detailed table")
    parser.add_argument("--targets", action="store_true",
                        help="only the issue's table: this branch against --reference, every "
                             "row measured in fresh processes in the same run")
    parser.add_argument("--reference", default="main",
                        help="git revision of the reference for --targets (default: main)")
    parser.add_argument("--bytecode", action="store_true",
                        help="--targets: the measured processes write and reuse byte code (in a "
                             "temporary folder), as an installed package does, even where "
                             "PYTHONDONTWRITEBYTECODE is set")
    parser.add_argument("--reference-transcription", default=PAPER_FORM,
                        help="the reference's transcription for --targets (default: the "
                             f"paper's {PAPER_FORM}; {FAST} isolates this branch's changes)")
    args = parser.parse_args(argv)
    if args.targets:
        print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores)")
        with tempfile.TemporaryDirectory(prefix="gaitopt-bytecode-") as bytecode:
            if args.bytecode:
                BYTECODE["dir"] = Path(bytecode)
                print("byte code written and reused by the measured processes")
            targets(args.reference, args.repeat, args.formulation, args.reference_transcription)
        print(f"load average after: {load_average()}")
        return
    grids = [tuple(int(k) for k in g.split(",")) for g in args.grids]
    print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores)")
    measures: list[Measure] = []
    for knots in grids:
        k = (knots[0], knots[1])
        for m in bench_grid(k, args.repeat, args.formulation, args.transcription):
            measures.append(m)
            print(f"  {k[0]}+{k[1]} {m.name:<20} {m.wall_s:8.3f} s  it {m.iterations:4d}  "
                  f"{'ok' if m.success else 'FAILED'}", flush=True)
    print()
    print(table(measures))
    print()
    print(NOTE)
    print()
    by = {(m.name, m.knots): m for m in measures}
    fresh, cached = by.get(("cold (fresh)", (8, 5))), by.get(("cold (cache built)", (8, 5)))
    if fresh and cached:
        print(f"NLP build (8+5, cold fresh - cold cached): {fresh.wall_s - cached.wall_s:.2f} s")
    fresh, cached = by.get(("cold (fresh)", (40, 10))), by.get(("cold (cache built)", (40, 10)))
    if fresh and cached:
        print(f"NLP build (40+10 and its 8+5 stages): {fresh.wall_s - cached.wall_s:.2f} s")
    if fresh:
        for name, wall, calls in PAPER:
            print(f"vs {name}: {wall / fresh.wall_s:,.0f} x less wall time (cold fresh, "
                  f"40+10), {calls / max(fresh.state_calls, 1):,.1f} x fewer state-equation "
                  "calls")
    cold = by.get(("cold (fresh)", (8, 5)))
    if cold:
        for name, wall, calls in PAPER:
            print(f"vs {name}: {wall / cold.wall_s:,.0f} x less wall time (cold fresh, 8+5), "
                  f"{calls / max(cold.state_calls, 1):,.1f} x fewer state-equation calls")
    print(f"load average after: {load_average()}")


if __name__ == "__main__":
    main()
