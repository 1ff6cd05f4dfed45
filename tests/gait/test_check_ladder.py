"""The check grid of a cost of transport on the heel-toe walk climbs the smoothing ladder
(gaitopt.gait.solve.staged.check_smoothings); the paper's cost and the two-phase walk solve
their check grid in one stage, as before."""

from __future__ import annotations

import pytest

from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.solve.staged import check_smoothings, smoothing_ladder
from gaitopt.robot import load_model


def test_the_ladder_for_costs_of_transport_with_feet_only() -> None:
    seven = load_model("seven-link")
    scale = model_scale(seven)
    for cost in ("work", "metabolic"):
        options = options_for_model(seven, GaitOptions(gait="heel-toe", cost=cost))
        steps = check_smoothings(options, scale)
        assert steps == smoothing_ladder(options.cost_smoothing, scale)
        assert len(steps) == 2 and steps[0] > steps[1] > options.cost_smoothing
        assert steps[0] == pytest.approx(scale.power(1.0), rel=1e-12)
    paper = options_for_model(seven, GaitOptions(gait="heel-toe"))
    assert check_smoothings(paper, scale) == []
    walk = GaitOptions(cost="metabolic")  # the five-link's two-phase walk
    assert check_smoothings(walk, model_scale(load_model("five-link"))) == []


@pytest.mark.slow
def test_the_check_grid_of_a_metabolic_walk_with_feet_converges() -> None:
    """The seven-link's metabolic walk (4.8 W/kg, 78 m/min, a coarse 12 + 8 grid) solved cold,
    then from its gait file with its check grid: every ladder stage and the check grid
    converge, and the file's estimates exist (docs/costs.md, "The accuracy pass")."""
    from gaitopt.gait.api import solve_staged_run
    from gaitopt.gait.solve.accuracy import accuracy_record
    from gaitopt.gait.solve.record import gait_from_run

    seven = load_model("seven-link")
    options = GaitOptions(gait="heel-toe", cost="metabolic", resting_power=4.8, speed=1.3,
                          knots=(12, 8), max_iter=3000)
    cold = solve_staged_run(seven, options, refine=False)
    assert cold.success, cold.result.status
    run = solve_staged_run(seven, options, warm_start=gait_from_run(cold), refine=False,
                           check_warm_start=True)
    names = [s.name for s in run.stages]
    checks = [s for s in run.stages if s.name.startswith("check grid")]
    assert [s.name for s in checks][-1] == "check grid", names
    assert len(checks) == 3 and all(s.success for s in checks), [
        (s.name, s.status, s.iterations) for s in checks]
    record = accuracy_record(run)
    assert record["cost_error"] is not None
    assert abs(run.result.objective - cold.result.objective) <= 1e-5 * abs(cold.result.objective)
