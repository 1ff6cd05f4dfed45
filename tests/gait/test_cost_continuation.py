"""The smoothing ladder of a cost with kinks (gaitopt.gait.solve.cost_continuation): which costs
take it (from the costs' declared traits), the order of its stages, and on a small grid that
it ends at an optimum of the requested cost no dearer than the paper's optimum it starts from."""

from __future__ import annotations

from typing import Any

import pytest

from gaitopt.gait.formulations import cost
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import model_scale
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.cost_continuation import (
    climb_ladder,
    continues_from_paper,
    smoothing_ladder,
)
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
