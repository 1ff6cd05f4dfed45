"""Benchmark: warm starts across grids with mapped multipliers (gaitopt.ocp.regrid) or values.

Every case is solved twice in this process by ``solve_walking``: first as main does
(``gaitopt.gait.solve.staged.REGRID_MOVES`` empty: a move to another grid starts IPOPT from the
previous solution's values only, with ``PRIMAL_WARM_OPTIONS``), then with the mapped
multipliers on the grid moves ``--moves`` for every contact sequence (``REGRID_MOVES``;
default the check grid only), the transcription's ``WARM_START_OPTIONS`` with ``--mu`` as
IPOPT's initial barrier (``REGRID_OPTIONS``; default 1e-4). With the defaults, the mapped run
of the heel-toe walk is what ``solve_walking`` does by default; the two-phase walks keep
main's behaviour by default (the first run). The transcriptions are built by the first run
and reused by the second, so the stage times compare solves, not builds (the second run builds
one more IPOPT instance per grid for the warm-start options, from the derivatives already
built).

Printed per case and run: the iterations of the cross-grid stages (``target grid``, ``target
grid, all free``, ``check grid``), their wall time, every stage's iterations summed, the final
cost (the target grid's), the check grid's cost, and the larger relative difference of the two
from main's (the optima must not change: <= 1e-6 is the same optimum); then the totals and
ratios over the cases where both runs reached the same optima.

Cases (``--cases``, default all but ``seven``): ``five`` the five-link default (16 + 6 cosine
knots, jumps control model) at 3, 12, 36, 60 m/min, with and without ankle torques and liftoff
impulse; ``paper`` the paper control model on uniform 40 + 10 knots at 12 m/min; ``full`` full
coordinates at 12 and 48 m/min; ``seven`` the seven-link heel-toe walk on 24 + 16 knots at
``--seven-speeds`` (default 12 m/min; about a minute per run).

Run: ``python bench/regrid.py [--cases five paper full seven] [--mu 1e-4]
[--moves target check] [--seven-speeds 12 24 36 48]``
"""

from __future__ import annotations

import argparse
import math
import os
import time
from dataclasses import dataclass

from gaitopt.gait.options.gait_options import GAITS, GaitOptions
from gaitopt.gait.solve import staged as walking
from gaitopt.gait.solve.staged import solve_walking
from gaitopt.robot import load_model

#: The stages that move between grids (cold solves without ``mesh_tol``).
CROSS_GRID = ("target grid", "target grid, all free", "check grid")


@dataclass(frozen=True)
class Case:
    """One solve to compare: a label, the built-in model and the options."""

    label: str
    model: str
    options: GaitOptions


def cases(groups: list[str], seven_speeds: list[float]) -> list[Case]:
    """The cases of ``groups`` (see the module docstring); the seven-link walk at
    ``seven_speeds`` (m/min)."""
    out: list[Case] = []
    if "five" in groups:
        for speed in (3, 12, 36, 60):
            for variant, flag in (("ankle+impulse", True), ("plain", False)):
                out.append(Case(f"five-link {variant} {speed} m/min", "five-link",
                                GaitOptions(speed=speed / 60, ankle=flag, impulse=flag)))
    if "paper" in groups:
        out.append(Case("paper model 40+10 uniform 12 m/min", "five-link",
                        GaitOptions(speed=0.2, knots=(40, 10), knot_spacing="uniform",
                                    control_model="paper")))
    if "full" in groups:
        for speed in (12, 48):
            out.append(Case(f"full coordinates {speed} m/min", "five-link",
                            GaitOptions(speed=speed / 60, formulation="full")))
    if "seven" in groups:
        for speed in seven_speeds:
            out.append(Case(f"seven-link heel-toe 24+16 {speed:g} m/min", "seven-link",
                            GaitOptions(speed=speed / 60, gait="heel-toe", knots=(24, 16),
                                        formulation="full")))
    return out


@dataclass(frozen=True)
class Run:
    """What one solve measured."""

    success: bool
    cost: float
    check_cost: float
    stage_iterations: dict[str, int]
    stage_seconds: dict[str, float]
    total_iterations: int
    seconds: float

    @property
    def cross_iterations(self) -> int:
        """Iterations of the cross-grid stages."""
        return sum(self.stage_iterations.get(s, 0) for s in CROSS_GRID)

    @property
    def cross_seconds(self) -> float:
        """Wall time of the cross-grid stages (s)."""
        return sum(self.stage_seconds.get(s, 0.0) for s in CROSS_GRID)


def run(case: Case, moves: frozenset[str], mu: float) -> Run:
    """Solve ``case`` with the multipliers mapped across the grid ``moves`` (none: main)."""
    walking.REGRID_MOVES = {kind: moves for kind in (*GAITS, "sequence")}
    walking.REGRID_OPTIONS = {"ipopt.mu_init": mu}
    start = time.perf_counter()
    sol = solve_walking(load_model(case.model), case.options)
    seconds = time.perf_counter() - start
    iters: dict[str, int] = {}
    secs: dict[str, float] = {}
    check = math.nan
    for st in sol.stages:
        if st.name == "check grid":
            check = st.objective if st.success else math.nan
        iters[st.name] = iters.get(st.name, 0) + st.iterations
        secs[st.name] = secs.get(st.name, 0.0) + st.wall_time_s
    return Run(sol.success, sol.result.objective, check, iters, secs,
               sum(st.iterations for st in sol.stages), seconds)


def row(label: str, r: Run) -> str:
    """One table row."""
    per = " ".join(f"{r.stage_iterations.get(s, 0):4d}" for s in CROSS_GRID)
    return (f"{label:44s} {per}  {r.cross_iterations:5d} {r.cross_seconds:7.2f}"
            f" {r.total_iterations:6d} {r.cost:14.8g} {r.check_cost:14.8g}"
            f" {'ok' if r.success else 'FAIL'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=["five", "paper", "full"],
                        choices=["five", "paper", "full", "seven"])
    parser.add_argument("--mu", type=float, default=1e-4,
                        help="IPOPT's initial barrier of the mapped warm starts")
    parser.add_argument("--moves", nargs="+", default=["check"],
                        choices=["target", "check", "refinement"],
                        help="the grid moves that map the multipliers in the mapped runs")
    parser.add_argument("--seven-speeds", nargs="+", type=float, default=[12.0],
                        help="speeds (m/min) of the seven-link case")
    args = parser.parse_args()
    moves = frozenset(args.moves)
    print(f"load average {os.getloadavg()[0]:.2f}; mapped runs: mu_init {args.mu:g}, moves "
          f"{', '.join(sorted(moves))}")
    print(f"{'case / run':44s} {'tgt':>4s} {'free':>4s} {'chk':>4s}  {'cross':>5s} "
          f"{'s':>7s} {'all':>6s} {'cost':>14s} {'check cost':>14s}")
    totals = {False: [0, 0.0], True: [0, 0.0]}
    worst = 0.0
    elsewhere: list[str] = []
    for case in cases(args.cases, args.seven_speeds):
        main_run = run(case, frozenset(), args.mu)
        mapped = run(case, moves, args.mu)
        rel = max(abs(mapped.cost - main_run.cost) / abs(main_run.cost),
                  abs(mapped.check_cost - main_run.check_cost) / abs(main_run.check_cost))
        print(row(f"{case.label}: main", main_run))
        print(row(f"{case.label}: mapped", mapped) + f"  rel. cost diff {rel:.1e}")
        if not (main_run.success and mapped.success) or not rel <= 1e-6:
            elsewhere.append(f"{case.label} ({rel:.1e})")
            continue
        worst = max(worst, rel)
        for key, r in ((False, main_run), (True, mapped)):
            totals[key][0] += r.cross_iterations
            totals[key][1] += r.cross_seconds
    (i0, s0), (i1, s1) = totals[False], totals[True]
    print(f"\ncross-grid stages over the cases on the same optimum: main {i0} iterations "
          f"{s0:.1f} s, mapped {i1} iterations {s1:.1f} s; ratio mapped/main: iterations "
          f"{i1 / max(i0, 1):.2f}, time {s1 / max(s0, 1e-9):.2f}; largest rel. cost diff "
          f"{worst:.1e}")
    print("elsewhere or failed: " + (", ".join(elsewhere) if elsewhere else "none"))
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
