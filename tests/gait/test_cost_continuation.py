"""The smoothing ladder of a cost with kinks (gaitopt.gait.solve.cost_continuation): which costs
take it (from the costs' declared traits), the order of its stages, and on a small grid that
it ends at an optimum of the requested cost no dearer than the paper's optimum it starts from."""

from __future__ import annotations

from typing import Any

import pytest

from gaitopt.gait.formulations import cost
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import cost_smoothing_for, options_for_model
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.cost_continuation import (
    climb_ladder,
    continues_from_paper,
    smoothing_ladder,
)
from gaitopt.gait.solve.transcriptions import NlpStructure
from gaitopt.ocp import Guess, Result
from gaitopt.robot import load_model
from tests.gait.conftest import SolveFn


def test_every_cost_declares_whether_it_is_smooth() -> None:
    assert set(cost.COST_TRAITS) == set(cost.COSTS)
    assert all(t.name == name for name, t in cost.COST_TRAITS.items())


@pytest.mark.parametrize(("changes", "expected"), [
    ({"cost": "paper"}, False),
    ({"cost": "work"}, True),
    ({"cost": "metabolic"}, True),
    ({"cost": "paper", "cost_regularization": 0.1}, True),
])
def test_the_costs_that_are_not_smooth_continue_from_the_paper_optimum(
        changes: dict[str, Any], expected: bool) -> None:
    assert continues_from_paper(GaitOptions.paper(**changes)) is expected


class _FakeResult:
    """Stands for a Result: only ``success`` is read by the ladder."""

    def __init__(self, success: bool) -> None:
        self.success = success


def test_the_ladder_sharpens_the_smoothing_and_stops_at_a_failure() -> None:
    """Stages at 1 W, 0.1 W, then the requested smoothing; the first from the start's values
    with the primal warm-start options, each later one from the previous result; a failed
    rung ends the ladder with that result."""
    calls: list[tuple[str, float, object, dict[str, Any]]] = []
    fail_at: set[str] = set()

    def stage(name: str, problem: GaitOptions, guess: Guess | Result,
              solver_options: dict[str, Any]) -> Result:
        calls.append((name, problem.cost_smoothing, guess, solver_options))
        return _FakeResult(name not in fail_at)  # type: ignore[return-value]

    options = GaitOptions.paper(cost="work", cost_smoothing=0.01)
    start = Guess(phases={}, parameters={})
    last = climb_ladder(options, start, model_scale(load_model("five-link")), stage)
    assert last.success
    assert [c[0] for c in calls] == ["work cost, eps 1 W", "work cost, eps 0.1 W", "work cost"]
    assert [c[1] for c in calls] == pytest.approx([1.0, 0.1, 0.01])
    assert calls[0][2] is start and "ipopt.mu_init" in calls[0][3]
    assert calls[1][3] == {} and calls[2][3] == {}
    assert calls[2][2] is not start
    calls.clear()
    fail_at.add("work cost, eps 0.1 W")
    last = climb_ladder(options, start, model_scale(load_model("five-link")), stage)
    assert not last.success and [c[0] for c in calls][-1] == "work cost, eps 0.1 W"


def test_no_ladder_when_the_requested_smoothing_is_coarse() -> None:
    assert smoothing_ladder(1.0) == []
    assert smoothing_ladder(0.5) == pytest.approx([1.0])


def test_the_continuation_lowers_the_requested_cost_on_a_small_grid(solved: SolveFn) -> None:
    """The five-link walk at 12 m/min on the paper's 8 + 5 knots: the work cost's solve runs
    the paper cost's stages, then its ladder, and ends at a converged optimum whose work cost
    is no higher than that of the paper's optimum (recomputed from the paper gait's file with
    the work cost): the ladder starts there, so a higher end would be a failed descent."""
    paper = solved(GaitOptions.paper()).gait
    work = solved(GaitOptions.paper(cost="work"))
    names = [s["name"] for s in work.gait.stages]
    assert work.gait.success
    assert any(n.startswith("paper cost: ") for n in names)
    assert [n for n in names if n.startswith("work cost")][:3] == [
        "work cost, eps 1 W", "work cost, eps 0.1 W", "work cost"]
    data = paper.to_dict()
    data["options"]["cost"] = "work"
    paper_as_work = cost.recompute_cost(Gait.from_dict(data))
    assert work.gait.cost_value <= paper_as_work * (1.0 + 1e-5)
    assert work.gait.cost_value < 0.9 * paper_as_work  # the paper's optimum is not the work's


def test_the_default_smoothing_follows_the_speed_in_powers_of_ten() -> None:
    """The reference 0.01 W up to sqrt(10) times 12 m/min on the five-link biped, 0.1 W
    above; the seven-link model's 0.01 W carried over as a power, ten times that at 80 m/min;
    a free speed takes the gait's default speed; a given smoothing is kept."""
    five, seven = load_model("five-link"), load_model("seven-link")
    scale = model_scale(five)
    assert cost_smoothing_for(scale, 0.01, 0.2) == 0.01
    assert cost_smoothing_for(scale, 0.01, 0.05) == 0.01
    assert cost_smoothing_for(scale, 0.01, 0.2 * 10**0.5 * 0.99) == 0.01
    assert cost_smoothing_for(scale, 0.01, 0.2 * 10**0.5 * 1.01) == pytest.approx(0.1, rel=1e-12)
    assert options_for_model(five, GaitOptions(speed=None)).cost_smoothing == 0.01
    power = model_scale(seven).power(0.01)
    at_80 = options_for_model(seven, GaitOptions(speed=80 / 60)).cost_smoothing
    assert at_80 == pytest.approx(10 * power, rel=1e-12)
    assert options_for_model(seven, GaitOptions(speed=0.2)).cost_smoothing == pytest.approx(
        power, rel=1e-12)
    assert options_for_model(seven, GaitOptions(speed=80 / 60, cost_smoothing=0.02)
                             ).cost_smoothing == 0.02


def test_a_smooth_costs_nlp_does_not_depend_on_the_smoothing() -> None:
    """The paper cost has no positive parts: its NLP structure (the transcription cache's
    key) is the same at any smoothing, so a sweep over speeds builds it once; a cost of
    transport's differs."""
    five = load_model("five-link")
    paper = GaitOptions.paper()
    assert NlpStructure.of(five, paper, (8, 5), None) == NlpStructure.of(
        five, paper.replace(cost_smoothing=0.1), (8, 5), None)
    work = GaitOptions.paper(cost="work")
    assert NlpStructure.of(five, work, (8, 5), None) != NlpStructure.of(
        five, work.replace(cost_smoothing=0.1), (8, 5), None)
