"""A warm start's gait file and accuracy (gait.solve.warm_accuracy): the grid a file was refined
to, and its estimate carried over when the warm start finds the file's own optimum again (no
check grid solved); at another speed the check grid is solved, restarted from the file's own
check-grid point, and no refinement round is spent on a missing estimate."""

from __future__ import annotations

import dataclasses

import pytest

from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.record import gait_from_run
from gaitopt.gait.solve.warm_accuracy import (
    ESTIMATE_KEYS,
    check_point,
    refined_grid,
    refined_knots,
)
from gaitopt.robot import load_model
from tests.gait.conftest import SolveFn

PHASES = ("single_support", "double_support")


@pytest.fixture(scope="module")
def refined_file(solved: SolveFn) -> Gait:
    """The default solve (12 m/min, knots left to the model: it refines itself, and is
    within its 1 % target on its first grid)."""
    gait = solved(GaitOptions()).gait
    assert gait.success
    assert gait.solver["accuracy"]["within_target"] is True
    return Gait.from_dict(gait.to_dict())


def with_accuracy(gait: Gait, **changes: object) -> Gait:
    record = {**gait.solver["accuracy"], **changes}
    return dataclasses.replace(gait, solver={**gait.solver, "accuracy": record})


def test_refined_knots_only_from_a_file_that_reached_its_target(refined_file: Gait) -> None:
    knots = refined_file.solver["accuracy"]["knots"]
    assert refined_knots(refined_file, PHASES) == knots
    assert refined_knots(refined_file, ("single_support",)) is None      # other phases
    assert refined_knots(with_accuracy(refined_file, within_target=False), PHASES) is None
    assert refined_knots(with_accuracy(refined_file, target=None), PHASES) is None  # knots given


def test_a_warm_start_that_finds_the_file_optimum_keeps_its_estimate(
        refined_file: Gait) -> None:
    run = solve_staged_run("five-link", GaitOptions(), warm_start=refined_file)
    assert run.success
    assert [s.name for s in run.stages] == ["warm start"]          # no check grid again
    gait = gait_from_run(run)
    record, old = gait.solver["accuracy"], refined_file.solver["accuracy"]
    assert record["estimate_from"] == "warm start"
    assert {k: record[k] for k in ESTIMATE_KEYS} == {k: old[k] for k in ESTIMATE_KEYS}
    assert record["within_target"] is True
    assert gait.cost_value == pytest.approx(refined_file.cost_value, rel=1e-5)
    # the file's check-grid point goes on with its estimate (a chain of warm starts keeps it)
    assert gait.solver["warm_start_check"] == refined_file.solver["warm_start_check"]


def test_a_warm_start_at_another_speed_solves_its_check_grid(refined_file: Gait) -> None:
    run = solve_staged_run("five-link", GaitOptions(speed=0.21), warm_start=refined_file)
    assert run.success
    names = [s.name for s in run.stages]
    assert names[0] == "warm start" and "check grid" in names
    record = gait_from_run(run).solver["accuracy"]
    assert "estimate_from" not in record
    assert record["cost_error"] is not None
    # within its target on the file's grid: no refinement round
    assert record["within_target"] is True and record["refinements"] == 0


def test_the_warm_start_solves_on_the_grid_the_file_was_refined_to(
        refined_file: Gait) -> None:
    # A file that says it reached its target on 24 + 8 knots: the warm start starts there
    # (its cost is the 16 + 6 grid's, so its estimate is not carried over: checked again).
    file = with_accuracy(refined_file, knots={"single_support": 24, "double_support": 8})
    run = solve_staged_run("five-link", GaitOptions(), warm_start=file)
    assert run.success
    assert run.stages[0].knots == (24, 8)
    record = gait_from_run(run).solver["accuracy"]
    assert record["knots"] == {"single_support": 24, "double_support": 8}
    assert "estimate_from" not in record and record["cost_error"] is not None


def test_the_file_keeps_its_check_grid_point(refined_file: Gait) -> None:
    point = check_point(refined_file)
    assert point is not None
    check, answer = refined_file.solver["accuracy"]["check_knots"], refined_file.solver[
        "accuracy"]["knots"]
    assert sum(check.values()) > sum(answer.values())
    assert point.w.size > len(refined_file.solver["warm_start"]["w"])   # the finer grid's NLP
    data = refined_file.to_dict()
    del data["solver"]["warm_start_check"]  # a file written before it existed
    assert check_point(Gait.from_dict(data)) is None


def test_the_check_grid_restarts_from_the_file_check_point(refined_file: Gait) -> None:
    # At another speed the check grid is solved either way, to the same optimum; from the
    # file's check point (values and multipliers of that very NLP at the file's speed) in
    # fewer iterations than from the warm start's answer mapped onto the check grid.
    data = refined_file.to_dict()
    del data["solver"]["warm_start_check"]
    without = Gait.from_dict(data)
    runs = [solve_staged_run("five-link", GaitOptions(speed=0.21), warm_start=g)
            for g in (refined_file, without)]
    assert all(run.success for run in runs)
    records = [gait_from_run(run).solver["accuracy"] for run in runs]
    assert records[0]["check_cost"] == pytest.approx(records[1]["check_cost"], rel=1e-5)
    assert records[0]["cost_error"] == pytest.approx(records[1]["cost_error"], rel=1e-2,
                                                     abs=1e-5 * abs(records[1]["check_cost"]))
    checks = [next(s for s in run.stages if s.name == "check grid") for run in runs]
    assert checks[0].iterations <= checks[1].iterations + 3


def test_the_warm_start_keeps_the_form_of_the_file_grid(refined_file: Gait) -> None:
    # A heel-toe file solved with the knots option (24, 16): four phases of 24 + 18 + 16 + 16
    # knots. The warm start states the grid as the file did (its check grid is then the
    # file's: 36 + 26 + 24 + 24, not 36 + 27 + 24 + 24 from the counts per phase).
    model = load_model("seven-link")
    options = options_for_model(model, GaitOptions())
    counts = {"foot_flat": 24, "heel_off": 18, "double_support": 16, "heel_rocker": 16}
    file = dataclasses.replace(
        with_accuracy(refined_file, knots=counts),
        options={**refined_file.options, "knots": [24, 16], "phase_shares": None})
    stated = refined_grid(file, model, options)
    assert stated is not None and tuple(stated.knots) == (24, 16)
    # counts the stated form does not give: the counts per phase
    other = {**counts, "heel_off": 19}
    by_counts = refined_grid(with_accuracy(file, knots=other), model, options)
    assert by_counts is not None and tuple(by_counts.knots) == tuple(other.values())
    assert refined_grid(with_accuracy(file, within_target=False), model, options) is None
