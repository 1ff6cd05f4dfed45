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

Run: ``python bench/gait.py [--repeat 3] [--grids 8,5 40,10] [--formulation full]``
"""

from __future__ import annotations

import argparse
import contextlib
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from gaitopt.gait.api import solve_gait_solution
from gaitopt.gait.gait_file import Gait
from gaitopt.gait.options import GaitOptions
from gaitopt.gait.record import gait_from_solution
from gaitopt.gait.solve import WalkingSolution, solve_walking
from gaitopt.gait.transcriptions import clear_cache
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


def measure(name: str, knots: tuple[int, int], run: Callable[[], WalkingSolution]
            ) -> tuple[Measure, WalkingSolution]:
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
            run: Callable[[], WalkingSolution]) -> tuple[Measure, WalkingSolution]:
    runs = [measure(name, knots, run) for _ in range(repeat)]
    return min(runs, key=lambda mr: mr[0].wall_s)


def bench_grid(knots: tuple[int, int], repeat: int,
               formulation: str = "reduced") -> list[Measure]:
    model = load_model("five-link")
    options = GaitOptions.paper(speed=SPEED, knots=knots,
                          formulation=formulation)  # type: ignore[arg-type]
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
    saved = Gait.from_dict(gait_from_solution(solution).to_dict())
    from_file, _ = best_of(repeat, f"file (speed +{(SPEED_STEP - 1) * 100:.0f} %)", knots,
                           lambda: solve_gait_solution(model, faster, warm_start=saved))
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


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3,
                        help="best of N for the cached-cold and warm solves")
    parser.add_argument("--grids", nargs="+", default=["8,5", "40,10"],
                        help="knots per phase, single,double")
    parser.add_argument("--formulation", choices=["reduced", "full"], default="reduced",
                        help="the walking problem's coordinates (docs/formulations.md)")
    args = parser.parse_args(argv)
    grids = [tuple(int(k) for k in g.split(",")) for g in args.grids]
    print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores)")
    measures: list[Measure] = []
    for knots in grids:
        k = (knots[0], knots[1])
        for m in bench_grid(k, args.repeat, args.formulation):
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
