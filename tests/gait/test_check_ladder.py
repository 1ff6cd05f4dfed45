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

