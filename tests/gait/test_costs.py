"""The family of costs: each converges, its saved value is what the file recomputes to, the
work cost is the integral of positive actuator power (computed independently on dense
samples), and the resting term scales with the step time."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.formulations import cost
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.gait.solve.cost_continuation import smoothing_ladder
from gaitopt.robot import load_model
from gaitopt.robot.biped import biped_of
from tests.gait.conftest import Solved

SolveFn = Callable[..., Solved]


def _positive_work_on_samples(gait: Gait) -> float:
    """int sum_a max(0, u_a w_a) dt over the dense samples (trapezoid), w_a from the samples'
    qd: joint rates, and for an ankle the absolute rate of the shank (torso + hip + knee)."""
    model, s = gait.model, gait.samples
    rates = np.zeros_like(s.u)
    for j, a in enumerate(model.actuators):
        if a.joint is not None:
            rates[:, j] = s.qd[:, model.joint_coordinate(a.joint)]
        else:
            link = model.link_index(model.contact(a.contact or "").link)
            rates[:, j] = sum(s.qd[:, model.coordinate_of_link(i)] for i in model.chain(link))
    power = np.maximum(s.u * rates, 0.0).sum(axis=1)
    return float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(s.t)))


@pytest.mark.parametrize("name", ["work", "metabolic"])
def test_each_cost_converges_and_recomputes(solved: SolveFn, name: str) -> None:
    gait = solved(GaitOptions.paper(cost=name)).gait  # type: ignore[arg-type]
    assert gait.success
    assert gait.cost["name"] == name and name in gait.cost["formula"]
    assert cost.recompute_cost(gait) == pytest.approx(gait.cost_value, rel=1e-6)
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


def test_work_cost_is_the_positive_actuator_work(solved: SolveFn) -> None:
    """Independently of the solver's smoothing and quadrature: the positive work of the
    torques on the dense samples, over weight x step length, within the smoothing's bound
    (n_a eps T / (2 W L)) and the grid's quadrature error of the kinked integrand (a few per
    cent at 16 + 6 knots)."""
    gait = solved(GaitOptions.paper(cost="work", impulse=False, knots=(16, 6))).gait
    assert gait.success
    model = gait.model
    denominator = cost.weight(model) * gait.step_length
    independent = _positive_work_on_samples(gait) / denominator
    smoothing = model.nu * 0.01 * gait.step_time / (2.0 * denominator)
    assert gait.cost_value == pytest.approx(independent, rel=0.05, abs=smoothing)


def test_resting_term_scales_exactly_with_step_time() -> None:
    model = load_model("five-link")
    options = GaitOptions.paper(cost="metabolic", resting_power=1.5)
    rest = [cost.parameter_cost(model, options, [step, 0.5, 0.0]) for step in (0.2, 0.4, 0.8)]
    np.testing.assert_allclose(rest, [1.5 * model.total_mass * t for t in (0.4, 0.8, 1.6)])
    assert cost.parameter_cost(model, GaitOptions.paper(cost="work"), [0.2, 0.5, 0.0]) == 0.0


def test_metabolic_cost_changes_by_the_resting_energy(solved: SolveFn) -> None:
    """The same gait costs exactly (delta P_rest) m T / (W L) more with a larger resting
    power: recomputed from the file with the option changed."""
    gait = solved(GaitOptions.paper(cost="metabolic")).gait
    data = gait.to_dict()
    data["options"]["resting_power"] = gait.options["resting_power"] + 0.5
    changed = Gait.from_dict(data)
    model = gait.model
    expected = 0.5 * model.total_mass * gait.step_time / (cost.weight(model) * gait.step_length)
    assert cost.recompute_cost(changed) - cost.recompute_cost(gait) == pytest.approx(
        expected, rel=1e-9)


@pytest.mark.parametrize(("changes", "message"), [
    ({"cost": "fun"}, "cost = 'fun': must be one of paper, work, metabolic"),
    ({"efficiency_positive": 0.0}, "efficiency_positive = 0: must be > 0"),
    ({"efficiency_negative": -1.2}, "efficiency_negative = -1.2: must be > 0"),
    ({"resting_power": -1.0}, "resting_power = -1: must be >= 0"),
    ({"cost_regularization": -0.1}, "cost_regularization = -0.1: must be >= 0"),
])
def test_bad_cost_options_name_the_field(changes: dict[str, object], message: str) -> None:
    legs = biped_of(load_model("five-link"))
    with pytest.raises(GaitOptionsError, match=message):
        validate_options(GaitOptions.paper().replace(**changes), legs)


def test_smoothing_ladder_divides_by_ten_down_to_the_request() -> None:
    """The stages before the requested smoothing: 1 W, then a tenth each, never the request
    itself (the last stage solves it) and nothing when the request is at least 1 W."""
    assert smoothing_ladder(0.01) == pytest.approx([1.0, 0.1])
    assert smoothing_ladder(0.05) == pytest.approx([1.0, 0.1])
    assert smoothing_ladder(0.1) == pytest.approx([1.0])
    assert smoothing_ladder(1.0) == [] and smoothing_ladder(2.0) == []


def test_the_torque_rate_term_is_in_the_saved_cost_and_recomputes(solved: SolveFn) -> None:
    """With ``torque_rate_time`` the saved cost holds the term ``r sum (du)^2 / h`` of every
    phase's knot torques (independently recomputed here), and verify recomputes it."""
    tau = 0.05
    plain = solved(GaitOptions(knots=(16, 6))).gait
    rated = solved(GaitOptions(knots=(16, 6), torque_rate_time=tau)).gait
    assert rated.success and f"({tau:g} s)^2" in rated.cost["formula"]
    model = rated.model
    weights = cost.torque_rate_weights(model, GaitOptions.from_dict(dict(rated.options)))
    r = np.array([weights[a.name] for a in model.actuators])
    term = sum(float(np.sum((np.diff(ph.u, axis=0) ** 2) @ r / np.diff(ph.t)))
               for ph in rated.phases)
    without = cost.recompute_cost(rated) - term / cost.denominator(
        model, GaitOptions.from_dict(dict(rated.options)),
        [rated.step_length, rated.speed, rated.parameters["liftoff_impulse"]])
    assert term > 0.0
    assert cost.recompute_cost(rated) == pytest.approx(rated.cost_value, rel=1e-6)
    # The term prices the torques' changes: the optimum without it is cheaper in the plain
    # cost, and smooths less.
    assert without >= plain.cost_value * (1.0 - 1e-5)
    report = verify_gait(rated)
    assert report.passed, report.failed_ids


def test_the_smoothing_share_is_the_cost_without_smoothing(solved: SolveFn) -> None:
    """``solver.accuracy.smoothing``: the cost of the same motion with exact positive parts
    lies below the smoothed cost by at most the smoothing's bound n_a eps T / (2 W L), and
    agrees with the positive work on the dense samples (an independent quadrature) to the
    grid's quadrature error of the kinked integrand; the paper's cost has none."""
    gait = solved(GaitOptions.paper(cost="work", impulse=False, knots=(16, 6))).gait
    record = gait.solver["accuracy"]["smoothing"]
    assert record == cost.smoothing_record(gait)
    eps = record["cost_smoothing"]
    assert eps == gait.options["cost_smoothing"] > 0.0
    denominator = cost.weight(gait.model) * gait.step_length
    bound = gait.model.nu * eps * gait.step_time / (2.0 * denominator)
    gap = gait.cost_value - record["unsmoothed_cost"]
    assert 0.0 < gap <= bound * (1.0 + 1e-9)
    assert record["share"] == pytest.approx(gap / gait.cost_value, rel=1e-5)
    # 5.1 % apart on 16 + 6 knots: the kinks of max(0, p) between knots
    assert record["unsmoothed_cost"] == pytest.approx(
        _positive_work_on_samples(gait) / denominator, rel=0.08)
    # a vanishing smoothing recomputes the unsmoothed cost (continuity in eps)
    sharp = dataclasses.replace(gait, options={**dict(gait.options), "cost_smoothing": 1e-12})
    assert cost.recompute_cost(sharp) == pytest.approx(record["unsmoothed_cost"], rel=1e-9)
    assert "smoothing" not in solved(GaitOptions.paper()).gait.solver["accuracy"]


def test_a_malformed_smoothing_record_names_the_field(solved: SolveFn) -> None:
    data = solved(GaitOptions.paper(cost="work", impulse=False, knots=(16, 6))).gait.to_dict()
    data["solver"]["accuracy"]["smoothing"] = {"cost_smoothing": 0.01, "share": "half"}
    with pytest.raises(GaitFileError, match="solver.accuracy.smoothing"):
        Gait.from_dict(data)
    data["solver"]["accuracy"]["smoothing"] = {"cost_smoothing": 0.01, "share": "half",
                                               "unsmoothed_cost": 0.003}
    with pytest.raises(GaitFileError, match="solver.accuracy.smoothing.share"):
        Gait.from_dict(data)
