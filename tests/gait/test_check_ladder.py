"""The check grid of a cost of transport on the heel-toe walk climbs the smoothing ladder
(gaitopt.gait.solve.cost_continuation.check_smoothings); the paper's cost and the two-phase
walk solve their check grid in one stage, as before."""

from __future__ import annotations

import pytest

from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.solve.cost_continuation import check_smoothings, smoothing_ladder
from gaitopt.robot import load_model


def test_the_ladder_for_costs_of_transport_with_feet_only() -> None:
    seven = load_model("seven-link")
    scale = model_scale(seven)
    for cost in ("work", "metabolic"):
        options = options_for_model(seven, GaitOptions(gait="heel-toe", cost=cost))
        steps = check_smoothings(options, scale)
        assert steps == smoothing_ladder(options.cost_smoothing, scale)
        assert steps and all(a > b for a, b in zip(steps, steps[1:], strict=False))
        assert steps[-1] > options.cost_smoothing
        assert steps[0] == pytest.approx(scale.power(1.0), rel=1e-12)
    paper = options_for_model(seven, GaitOptions(gait="heel-toe"))
    assert check_smoothings(paper, scale) == []
    walk = GaitOptions(cost="metabolic")  # the five-link's two-phase walk
    assert check_smoothings(walk, model_scale(load_model("five-link"))) == []



class _Point:
    """Stands for a Result: ``success`` and ``parameters`` are what the check grid reads."""

    def __init__(self, speed: float, step_length: float) -> None:
        self.success = True
        self.parameters = {"speed": speed, "step_length": step_length}


def test_the_check_ladder_holds_the_step_until_the_requested_smoothing(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The coarse rungs of the check grid's ladder hold the step length and the speed at the
    target grid's optimum (at 1.6 W the seven-link's slow work optimum moved from 19 to
    34 m/min); the last stage, at the requested smoothing, frees them within the options'
    own bounds."""
    from gaitopt.gait.formulations.step_parameters import parameter_bounds
    from gaitopt.gait.solve import staged

    seven = load_model("seven-link")
    options = options_for_model(seven, GaitOptions(gait="heel-toe", cost="work", speed=None))
    run = staged._Run(seven, options, None, None)
    calls: list[tuple[str, float, dict[str, object]]] = []

    def stage(name: str, grid: object, relax: object, guess: object,
              bounds: dict[str, object], **kw: object) -> _Point:
        problem = kw.get("problem") or options
        calls.append((name, problem.cost_smoothing, dict(bounds)))  # type: ignore[attr-defined]
        return _Point(1.0, 1.0)  # each rung's optimum elsewhere: the hold must not follow it

    monkeypatch.setattr(run, "stage", stage)
    monkeypatch.setattr(run, "grid_start", lambda grid, result, move: result)
    answer = _Point(0.3178, 0.3687)
    run.check(answer)  # type: ignore[arg-type]
    rungs = check_smoothings(options, model_scale(seven))
    assert [c[1] for c in calls] == [*rungs, options.cost_smoothing]
    free = parameter_bounds(options)
    for _, _, bounds in calls[:-1]:
        assert bounds["speed"] == (answer.parameters["speed"],) * 2
        assert bounds["step_length"] == (answer.parameters["step_length"],) * 2
    assert calls[-1][2]["speed"] == free["speed"]
    assert calls[-1][2]["step_length"] == free["step_length"]
    assert free["speed"][0] < answer.parameters["speed"] < free["speed"][1]
