"""A sweep point started from a gait file restarts its check grid from the file's check-grid
point (``solver.warm_start_check``), as a single warm-started solve does."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gaitopt.gait.api import solve_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.solve.warm_accuracy import check_point
from gaitopt.robot import RobotModel
from gaitopt.study.worker import PointTask, SavedGait, _warm_start, solve_point


def options(model: RobotModel) -> GaitOptions:
    """A sweep point's options: the model's defaults applied, the grid given."""
    return options_for_model(model, GaitOptions(speed=0.3, knots=(16, 6)))


@pytest.fixture(scope="module")
def saved(five_link: RobotModel) -> SavedGait:
    gait = solve_gait(five_link, options(five_link))
    assert gait.success and "warm_start_check" in gait.solver
    return SavedGait("neighbour.gait.json", json.dumps(gait.to_dict()))


def task(model: RobotModel, warm: SavedGait, *, check_grid: bool) -> PointTask:
    return PointTask(key="k", model=model, options=options(model), variant="ankle+impulse",
                     speed_mode="fixed", structure="s", warm=warm, relfile="k.gait.json",
                     check_grid=check_grid)


def test_the_check_point_travels_with_the_file(five_link: RobotModel,
                                               saved: SavedGait) -> None:
    from gaitopt.gait.record.file import Gait

    expected = check_point(Gait.from_dict(json.loads(saved.text)))
    assert expected is not None
    _, how, check = _warm_start(task(five_link, saved, check_grid=True))
    assert how == "file" and check is not None
    np.testing.assert_array_equal(np.asarray(check.w), np.asarray(expected.w))
    assert _warm_start(task(five_link, saved, check_grid=False))[2] is None


def test_a_point_from_a_file_solves_its_check_grid_to_the_same_estimate(
        five_link: RobotModel, saved: SavedGait) -> None:
    outcome = solve_point(task(five_link, saved, check_grid=True))
    assert outcome.gait is not None and outcome.warm == "file"
    accuracy = outcome.gait["solver"]["accuracy"]
    original = json.loads(saved.text)["solver"]["accuracy"]
    assert accuracy["check_cost"] == pytest.approx(original["check_cost"], rel=1e-5)
