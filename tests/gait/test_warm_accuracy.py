"""A warm start's gait file and accuracy (gait.solve.warm_accuracy): the grid a file was refined
to, and its estimate carried over when the warm start finds the file's own optimum again (no
check grid solved); at another speed the check grid is solved and no refinement round is
spent on a missing estimate."""

from __future__ import annotations

import dataclasses

import pytest

from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.record import gait_from_run
from gaitopt.gait.solve.warm_accuracy import ESTIMATE_KEYS, refined_knots
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
