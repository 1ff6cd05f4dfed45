"""Bad requests get clear errors before any solve; a failed solve is reported as failed."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from gaitopt.gait.api import solve_gait, solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError
from gaitopt.gait.record.file import FAILED_WARNING, Gait, GaitFileError
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run
from gaitopt.robot import ModelError, load_model
from gaitopt.robot.biped import BipedStructureError
from gaitopt.robot.loader import builtin_text
from tests.gait.conftest import Solved

#: A solve forced to fail: 3 IPOPT iterations per stage and no speed continuation.
FAILING = GaitOptions.paper(max_iter=3, continuation=False)


@pytest.fixture
def no_solve(monkeypatch: pytest.MonkeyPatch) -> None:
    """Any attempt to build or run an NLP fails the test: errors must come before."""
    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("a solve was started for a request that should be refused")

    monkeypatch.setattr("gaitopt.gait.solve.staged.transcription_for", refuse)


def one_legged_model_file(folder: Path) -> Path:
    """The five-link model with contact tip_2 (and its ankle actuator) deleted."""
    data = yaml.safe_load(builtin_text("five-link"))
    data["name"] = "one-tip"
    data["contacts"] = [c for c in data["contacts"] if c["name"] != "tip_2"]
    data["actuators"] = [a for a in data["actuators"] if a.get("contact") != "tip_2"]
    path = folder / "one-tip.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


BAD_OPTIONS: dict[str, tuple[dict[str, Any], tuple[str, ...]]] = {
    "step longer than the legs reach": ({"step_length": 2.0}, ("step_length", "reach")),
    "negative speed": ({"speed": -0.05}, ("speed", "> 0")),
    "zero speed": ({"speed": 0.0}, ("speed", "> 0")),
    "free speed with a bound at 0": ({"speed": None, "speed_bounds": (0.0, 1.0)},
                                     ("speed_bounds", "> 0")),
    "torso bounds exclude upright": ({"torso_bounds": (0.1, 0.5)}, ("torso_bounds", "0")),
    "too few single-support knots": ({"knots": (2, 5)}, ("knots",)),
    "too few double-support knots": ({"knots": (8, 1)}, ("knots",)),
    "non-integer knots": ({"knots": (8.0, 5)}, ("knots", "integers")),
    "too many knots": ({"knots": (8, 1000)}, ("knots", "400")),
    "single support fraction zero": ({"single_support_fraction": 0.0},
                                     ("single_support_fraction",)),
    "single support fraction above 1": ({"single_support_fraction": 1.2},
                                        ("single_support_fraction",)),
    "negative friction": ({"friction": -0.5}, ("friction", "> 0")),
    "NaN step length": ({"step_length": float("nan")}, ("step_length", "finite")),
    "inverted step bounds": ({"step_length_bounds": (0.5, 0.1)}, ("step_length_bounds",)),
    "step time and step length": ({"step_time": 0.5, "step_length": 0.1},
                                  ("step_time", "step_length", "at most one")),
    "negative step time": ({"step_time": -0.5}, ("step_time", "> 0")),
    "step time too long for the speed": ({"step_time": 8.0},
                                         ("step_time", "step length 1.6 m", "reach")),
    "step time too short for any speed": ({"speed": None, "step_time": 0.01},
                                          ("step_time", "speed_bounds")),
}


@pytest.mark.parametrize("case", list(BAD_OPTIONS))
def test_bad_options_raise_before_any_solve(no_solve: None, case: str) -> None:
    changes, words = BAD_OPTIONS[case]
    with pytest.raises(GaitOptionsError) as info:
        solve_gait("five-link", GaitOptions.paper(**changes))
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, message


def test_model_without_two_legs_raises_before_any_solve(no_solve: None, tmp_path: Path) -> None:
    model = load_model(one_legged_model_file(tmp_path))  # a valid model, not a biped
    # The default formulation follows the model (full coordinates for a model that is not
    # the five-link shape): its contact sequence check says what is missing.
    with pytest.raises(GaitOptionsError, match="two contact points"):
        solve_gait(model, GaitOptions.paper())
    with pytest.raises(BipedStructureError, match="two contact points"):
        solve_gait(model, GaitOptions.paper(formulation="reduced"))


def test_a_forced_failure_is_reported_as_failed(tmp_path: Path) -> None:
    solution = solve_staged_run("five-link", FAILING)
    assert not solution.success
    assert solution.stages and not any(s.success for s in solution.stages)
    assert solution.failed_stage is not None
    assert solution.failed_stage.name == "relaxed contact"
    assert solution.failed_stage.status == "Maximum_Iterations_Exceeded"
    gait = gait_from_run(solution)
    assert not gait.success and gait.status == "Maximum_Iterations_Exceeded"
    assert [s["name"] for s in gait.solver["stages"]] == [s.name for s in solution.stages]
    target = tmp_path / "failed.gait.json"
    with pytest.raises(GaitFileError, match="refusing to save a gait whose solve failed"):
        gait.save(target)
    assert not target.exists() and list(tmp_path.iterdir()) == []
    # Kept on request, a failed gait says so and still loads as failed.
    gait.save(target, allow_failed=True)
    assert FAILED_WARNING in target.read_text()
    assert not Gait.load(target).success


def test_missing_model_file_raises_model_error(no_solve: None, tmp_path: Path) -> None:
    with pytest.raises(ModelError, match="no-such.yaml"):
        solve_gait(tmp_path / "no-such.yaml", GaitOptions.paper())


def test_motion_out_of_reach_between_knots_is_a_clear_error(default_solved: Solved) -> None:
    """A solution whose interpolated motion leaves the stance leg's reach between knots (the
    reach is enforced at knots and midpoints only) cannot be recorded: a clear error that
    names the phase and the times, not a NaN-filled gait or a traceback from the gait file."""
    solution = default_solved.solution
    single = solution.result.phases[0]
    r = single.states.index("r")
    xdot = single.xdot.copy()
    xdot[3, r] = 50.0  # the cubic between knots 3 and 4 bulges far beyond the leg's reach
    bulged = dataclasses.replace(single, xdot=xdot)
    result = dataclasses.replace(solution.result,
                                 phases=(bulged, *solution.result.phases[1:]))
    broken = dataclasses.replace(solution, result=result)
    t3, t4 = single.t[3], single.t[4]
    with pytest.raises(MotionOutOfReachError, match="phase single_support") as err:
        gait_from_run(broken)
    times = [float(v) for v in re.findall(r"t = ([0-9.]+) to ([0-9.]+) s", str(err.value))[0]]
    assert t3 < times[0] <= times[1] < t4
    # The unmodified solution records.
    assert np.all(np.isfinite(gait_from_run(solution).samples.q))
