"""Which Hermite-Simpson form should be the walking default: both forms on the same points and
grids, their costs against the grid error.

For each variant and speed (cold solves from scratch with the default stages, as
``bench/gait_grid.py``) and each grid of ``--grids``, solves the compressed form
(``hermite-simpson``) and the separated one (``hermite-simpson-separated``), then ``verify``;
``--fine`` solves the separated form once more on a fine grid (the two forms converge to the
same limit, ``docs/results/benchmarks-gait.md``). Prints one row per point: for every grid and form
converged/verify, wall time and cost; the relative difference of the two forms on each grid;
the grid error (the change of the cost from the first grid to the second, and to the fine
grid). A form difference well inside the grid error means the two reach the same optimum
within the discretization error.

Run: ``python bench/form_choice.py [--speeds 3 12 24 36 48 60] [--variants ...]
[--grids 16,6 24,8] [--fine 48,16] [--json FILE]``
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from gait_grid import VARIANTS, load_average, verify_summary  # noqa: E402

from gaitopt.gait.api import solve_staged_run  # noqa: E402
from gaitopt.gait.options.gait_options import GaitOptions  # noqa: E402
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run  # noqa: E402

FORMS = ("hermite-simpson", "hermite-simpson-separated")
SHORT_FORM = {"hermite-simpson": "compressed", "hermite-simpson-separated": "separated"}


@dataclass(frozen=True)
class Solve:
    variant: str
    speed_m_min: float
    knots: tuple[int, int]
    form: str
    success: bool
    verify: str
    wall_s: float
    iterations: int
    cost: float
    step_length: float


def solve(variant: str, speed_m_min: float, knots: tuple[int, int], form: str,
          check: bool) -> Solve:
    """One cold solve of the default problem (the variant, speed, grid and form given)."""
    options = GaitOptions(speed=speed_m_min / 60.0, knots=knots,
                          transcription=form,  # type: ignore[arg-type]
                          **VARIANTS[variant])
    start = time.perf_counter()
    solution = solve_staged_run("five-link", options)
    wall = time.perf_counter() - start
    try:
        gait = gait_from_run(solution) if solution.success else None
    except MotionOutOfReachError:
        gait = None
    nan = float("nan")
    return Solve(variant, speed_m_min, knots, form, gait is not None,
                 (verify_summary(gait) if check else "-") if gait else "-", wall,
                 sum(s.iterations for s in solution.stages),
                 gait.cost_value if gait else nan, gait.step_length if gait else nan)


def pct(a: float, b: float) -> str:
    """``(a - b) / b`` in percent, signed."""
    return f"{100.0 * (a - b) / b:+.3f} %"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--speeds", type=float, nargs="+", default=[3, 12, 24, 36, 48, 60],
                        help="speeds in m/min")
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--grids", nargs="+", default=["16,6", "24,8"],
                        help="knots per phase, single,double (each solved in both forms)")
    parser.add_argument("--fine", default=None,
                        help="a fine grid, single,double, solved in the separated form only")
    parser.add_argument("--no-verify", action="store_true", help="skip verify")
    parser.add_argument("--json", type=Path, help="also write the solves as JSON")
    args = parser.parse_args(argv)
    grids = [tuple(int(k) for k in g.split(",")) for g in args.grids]
    fine = tuple(int(k) for k in args.fine.split(",")) if args.fine else None

    print(f"load average before: {load_average()} (1, 5, 15 min; {os.cpu_count()} cores)")
    solves: list[Solve] = []
    for variant in args.variants:
        for speed in args.speeds:
            runs = [(g, f) for g in grids for f in FORMS]
            if fine is not None:
                runs.append((fine, FORMS[1]))
            for grid, form in runs:
                s = solve(variant, speed, (grid[0], grid[1]), form, not args.no_verify)
                solves.append(s)
                print(f"  {variant:<14} {speed:5.1f} m/min {grid[0]}+{grid[1]:<3} "
                      f"{SHORT_FORM[form]:<10} {'ok ' if s.success else 'FAIL'} "
                      f"{s.wall_s:6.2f} s  it {s.iterations:4d}  J {s.cost:9.3f}  "
                      f"verify {s.verify}", flush=True)
    by = {(s.variant, s.speed_m_min, s.knots, s.form): s for s in solves}
    g0 = grids[0]
    head = ["variant", "speed (m/min)"]
    for g in grids:
        for f in FORMS:
            head.append(f"{g[0]}+{g[1]} {SHORT_FORM[f]}: J, verify, wall (s)")
        head.append(f"{g[0]}+{g[1]} separated - compressed")
    for g in grids[1:]:
        head.append(f"grid error {g0[0]}+{g0[1]} -> {g[0]}+{g[1]} (separated)")
    if fine is not None:
        head.append(f"{fine[0]}+{fine[1]} separated: J")
        head.append(f"grid error {g0[0]}+{g0[1]} -> {fine[0]}+{fine[1]} (separated)")
    print("\n| " + " | ".join(head) + " |")
    print("|" + "|".join([":---", "---:"] + ["---:"] * (len(head) - 2)) + "|")
    for variant in args.variants:
        for speed in args.speeds:
            cells = [variant, f"{speed:g}"]
            for g in grids:
                got = [by[(variant, speed, g, f)] for f in FORMS]
                for s in got:
                    cells.append(f"{s.cost:.2f}, {s.verify if s.success else 'FAIL'}, "
                                 f"{s.wall_s:.1f}")
                cells.append(pct(got[1].cost, got[0].cost))
            base = by[(variant, speed, g0, FORMS[1])]
            for g in grids[1:]:
                cells.append(pct(base.cost, by[(variant, speed, g, FORMS[1])].cost))
            if fine is not None:
                f_s = by[(variant, speed, fine, FORMS[1])]
                cells += [f"{f_s.cost:.2f}", pct(base.cost, f_s.cost)]
            print("| " + " | ".join(cells) + " |")
    print("\n| grid | form | converged | verify passes | median wall (s) | total wall (s) | "
          "IPOPT iterations |")
    print("|:---|:---|---:|---:|---:|---:|---:|")
    for g in grids:
        for f in FORMS:
            pts = [s for s in solves if s.knots == g and s.form == f]
            walls = sorted(s.wall_s for s in pts)
            print(f"| {g[0]}+{g[1]} | {SHORT_FORM[f]} | {sum(s.success for s in pts)}/"
                  f"{len(pts)} | {sum(s.verify == 'pass' for s in pts)}/{len(pts)} | "
                  f"{walls[len(walls) // 2]:.2f} | {sum(walls):.1f} | "
                  f"{sum(s.iterations for s in pts)} |")
    print(f"load average after: {load_average()}")
    if args.json:
        args.json.write_text(json.dumps([asdict(s) for s in solves], indent=1))


if __name__ == "__main__":
    main()
