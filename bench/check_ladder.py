"""Benchmark: the check grid of a cost of transport, solved several ways from a gait file.

Solves the gait file's problem on its own grid (from the file's NLP point and multipliers),
then its check grid (:func:`gaitopt.gait.solve.check_grid.check_knots`: 1.5 times the knots)
from that optimum mapped onto the check grid with its multipliers
(:func:`gaitopt.ocp.regrid.regridded`), in one of these ways (``--way``):

* ``one``: one stage at the file's smoothing (the check grid as it was solved before the
  ladder);
* ``ladder``: the positive parts smoothed with 100 and 10 times the file's smoothing first
  (1.6 and 0.16 W on the seven-link), each stage from the last with its multipliers, then the
  file's (what the check grid did before ``check_holds_step``).

``--mu`` is IPOPT's initial barrier of every stage (1e-4: ``REGRID_OPTIONS``, the one-stage
check grid's; 1e-6: the transcription's warm start, the ladder's). Prints each stage (status,
iterations, cost, speed, step, violation, wall time) and the first-order estimates of the
relative errors of the cost, speed and step length from the two grids.

Run: ``python bench/check_ladder.py out/feet-costs/seven-link/metabolic-rest-4.8/gaits/\
ankle+impulse/speed-078.00m_min.gait.json --way ladder --mu 1e-6 [--max-iter 800]``
(docs/costs.md, "The accuracy pass").
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from gaitopt.gait.api import as_model, restart_point
from gaitopt.gait.formulations.select import stage_bounds
from gaitopt.gait.formulations.step_parameters import (
    Relaxation,
    parameter_bounds,
    with_step_time,
)
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.check_grid import check_knots, first_order_factor
from gaitopt.gait.solve.staged_run import converged_or_failed
from gaitopt.gait.solve.stages import PRIMAL_WARM_OPTIONS, fine_grid_options
from gaitopt.gait.solve.transcriptions import target_grid, transcription_for
from gaitopt.ocp import Result, WarmStart
from gaitopt.ocp.regrid import regridded


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gait", help="a converged gait file of a work or metabolic cost")
    parser.add_argument("--way", choices=("one", "ladder"), default="ladder")
    parser.add_argument("--mu", type=float, default=1e-6, help="IPOPT's initial barrier")
    parser.add_argument("--max-iter", type=int, default=3000)
    args = parser.parse_args()
    gait = Gait.load(args.gait)
    model = as_model(gait.model)
    opts = options_for_model(model, GaitOptions.from_dict(dict(gait.options)))
    warm = {"ipopt.mu_init": args.mu}
    print(f"{opts.cost} cost, resting power {opts.resting_power} W/kg, smoothing "
          f"{opts.cost_smoothing:.3g} W, knots {opts.knots}; the file: cost "
          f"{gait.cost_value:.6g}, {gait.speed * 60:.2f} m/min", flush=True)

    def stage(name: str, o: GaitOptions, guess: Result | WarmStart) -> Result:
        grid = target_grid(model, o)
        tr = transcription_for(model, o, grid)
        solver: dict[str, Any] = {**fine_grid_options(o), **PRIMAL_WARM_OPTIONS,
                                  "ipopt.max_iter": args.max_iter}
        start = time.perf_counter()
        r = converged_or_failed(tr.solve(
            guess, bounds=with_step_time(stage_bounds(tr, Relaxation(), o), o),
            parameters=parameter_bounds(o), options=solver, warm_start_multipliers=True,
            warm_start_options=warm))
        print(f"{name:26s} {r.status:28s} it {r.iterations:5d}  J {r.objective:.6g}  "
              f"v {r.parameters['speed'] * 60:.3f} m/min  L {r.parameters['step_length']:.4f} m"
              f"  viol {r.constraint_violation:.1e}  {time.perf_counter() - start:.0f} s",
              flush=True)
        return r

    point = restart_point(model, opts, gait)
    if point is None:
        raise SystemExit("the gait file keeps no NLP point for this problem")
    coarse = stage("the file's grid", opts, point)
    fine = opts.replace(knots=check_knots(opts.knots))
    start: Result | WarmStart = regridded(transcription_for(model, fine, target_grid(model, fine)),
                                          coarse)
    eps = opts.cost_smoothing
    if args.way == "ladder":
        for e in (100 * eps, 10 * eps):
            start = stage(f"check grid, eps {e:.3g} W", fine.replace(cost_smoothing=e), start)
            if not start.success:
                return
    check = stage("check grid", fine, start)
    if check.success and coarse.success:
        factor = first_order_factor(opts.knots[0], fine.knots[0], of_finer=False)
        rel = {k: factor * abs(coarse.parameters[k] - check.parameters[k]) / coarse.parameters[k]
               for k in ("speed", "step_length")}
        cost = factor * abs(coarse.objective - check.objective) / abs(coarse.objective)
        print(f"estimates: cost {cost:.2%}, speed {rel['speed']:.2%}, "
              f"step length {rel['step_length']:.2%}")


if __name__ == "__main__":
    main()
