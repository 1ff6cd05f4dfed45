"""The check grid of a cost of transport on the heel-toe walk is solved with the step length
and speed held first, then free, both at the requested smoothing
(gaitopt.gait.solve.cost_continuation.check_holds_step, gaitopt.gait.solve.staged._Run.check);
the paper's cost and the two-phase walk solve their check grid in one stage, as before."""

from __future__ import annotations

import pytest

from gaitopt.gait.formulations.step_parameters import parameter_bounds
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.solve import staged
from gaitopt.gait.solve.cost_continuation import (
    check_holds_step,
    check_smoothings,
    smoothing_ladder,
)
from gaitopt.robot import load_model


def test_the_held_check_for_costs_of_transport_with_feet_only() -> None:
    seven = load_model("seven-link")
    scale = model_scale(seven)
    for cost in ("work", "metabolic"):
        options = options_for_model(seven, GaitOptions(gait="heel-toe", cost=cost, speed=None))
        assert check_holds_step(options.replace(cost_smoothing=scale.power(0.1)), scale)
    assert not check_holds_step(options_for_model(seven, GaitOptions(gait="heel-toe")))
    assert not check_holds_step(GaitOptions(cost="metabolic"))  # the five-link's two-phase walk


class _Point:
    """Stands for a Result: ``success`` and ``parameters`` are what the check grid reads."""

    def __init__(self, speed: float, step_length: float) -> None:
        self.success = True
        self.parameters = {"speed": speed, "step_length": step_length}


def _check_stages(options: GaitOptions, answer: _Point, monkeypatch: pytest.MonkeyPatch
                  ) -> list[tuple[str, float, dict[str, object]]]:
    """The stages (name, smoothing, parameter bounds) :meth:`_Run.check` asks for from
    ``answer``, each returning an optimum elsewhere (which the check must not follow)."""
    run = staged._Run(load_model("seven-link"), options, None, None)
    calls: list[tuple[str, float, dict[str, object]]] = []

    def stage(name: str, grid: object, relax: object, guess: object,
              bounds: dict[str, object], **kw: object) -> _Point:
        problem = kw.get("problem") or options
        calls.append((name, problem.cost_smoothing, dict(bounds)))  # type: ignore[attr-defined]
        return _Point(1.0, 1.0)

    monkeypatch.setattr(run, "stage", stage)
    monkeypatch.setattr(run, "grid_start", lambda grid, result, move: result)
    run.check(answer)  # type: ignore[arg-type]
    return calls


def test_the_check_holds_the_step_then_frees_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """Work cost, speed free: the first stage holds the step length and the speed at the
    target grid's optimum, the second frees them within the options' own bounds; both at
    the requested smoothing (the ladder's 1.6 W moved the slow work optimum from 19 to
    34 m/min, docs/costs.md)."""
    seven = load_model("seven-link")
    options = options_for_model(seven, GaitOptions(gait="heel-toe", cost="work", speed=None))
    answer = _Point(0.3178, 0.3687)
    calls = _check_stages(options, answer, monkeypatch)
    assert len(calls) == 2
    assert all(c[1] == options.cost_smoothing for c in calls)
    held, free = calls[0][2], calls[1][2]
    assert held["speed"] == (answer.parameters["speed"],) * 2
    assert held["step_length"] == (answer.parameters["step_length"],) * 2
    bounds = parameter_bounds(options)
    assert free["speed"] == bounds["speed"] and free["step_length"] == bounds["step_length"]
    lo, hi = bounds["speed"]
    assert lo < answer.parameters["speed"] < hi


def test_the_paper_cost_checks_in_one_free_stage(monkeypatch: pytest.MonkeyPatch) -> None:
    seven = load_model("seven-link")
    options = options_for_model(seven, GaitOptions(gait="heel-toe", speed=None))
    calls = _check_stages(options, _Point(1.3, 0.69), monkeypatch)
    assert [c[0] for c in calls] == ["check grid"]
    assert calls[0][2]["speed"] == parameter_bounds(options)["speed"]


def test_below_the_ladders_second_rung_the_check_climbs_the_free_ladder(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """At the seven-link's 0.016 W (a solve below 36.5 m/min) the check grid climbs the
    whole ladder (1.6, 0.16 W), everything free, then the requested smoothing, as before
    (held at 0.016 W it took 2307 iterations, docs/costs.md); at 0.16 W (the study's
    smoothing) it holds the step instead."""
    seven = load_model("seven-link")
    scale = model_scale(seven)
    options = options_for_model(seven, GaitOptions(gait="heel-toe", cost="metabolic",
                                                   speed=None))
    fine = options.replace(cost_smoothing=scale.power(0.01))
    assert not check_holds_step(fine, scale)
    assert check_smoothings(fine, scale) == smoothing_ladder(fine.cost_smoothing, scale)
    calls = _check_stages(fine, _Point(0.3, 0.36), monkeypatch)
    assert [c[1] for c in calls] == pytest.approx(
        [scale.power(1.0), scale.power(0.1), fine.cost_smoothing], rel=1e-12)
    free = parameter_bounds(fine)
    assert all(c[2]["speed"] == free["speed"] for c in calls)
    coarse = options.replace(cost_smoothing=scale.power(0.1))
    assert check_holds_step(coarse, scale) and check_smoothings(coarse, scale) == []
    assert not check_smoothings(options_for_model(seven, GaitOptions(gait="heel-toe")), scale)


def test_free_phase_shares_hold_the_step_with_the_paper_cost(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The heel-toe walk with its shares free (the release of gaitopt solve): held, then
    free, with the paper's cost too (with the speed free the one free stage wandered off,
    docs/feet.md); the shares fixed keep one free stage, and so does the five-link walk."""
    seven = load_model("seven-link")
    options = options_for_model(seven, GaitOptions(gait="heel-toe", speed=None,
                                                   free_phase_fractions=True))
    assert staged.holds_free_shares(options)
    answer = _Point(0.9727, 0.6023)
    calls = _check_stages(options, answer, monkeypatch)
    assert [c[0] for c in calls] == ["check grid, step held", "check grid"]
    assert calls[0][2]["speed"] == (answer.parameters["speed"],) * 2
    assert calls[1][2]["speed"] == parameter_bounds(options)["speed"]
    assert not staged.holds_free_shares(options.replace(free_phase_fractions=False))
    five = load_model("five-link")
    assert not staged.holds_free_shares(options_for_model(
        five, GaitOptions(formulation="full", free_phase_fractions=True)))
