"""Failures that explain themselves: at the best point a failed solve found, which
constraints are violated or binding, in words and numbers, and what the user can change.

A grid too coarse for the motion does not make the NLP fail (3 + 2 knots converge at 12 and
60 m/min); it shows as a converged solution whose motion leaves a leg's reach between knots,
which is refused with advice to use a finer grid (tests/gait/test_walking_errors.py and
tests/gait/test_cli_gait.py)."""

from __future__ import annotations

import copy

from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.api import solve_gait_solution
from gaitopt.gait.diagnose import diagnose
from gaitopt.gait.options import GaitOptions
from gaitopt.robot import load_model, model_from_dict


def _weak_biped() -> object:
    """The five-link model with every torque bound at 5 N m: too weak to walk (a bent knee
    under the body's weight alone needs tens of N m)."""
    data = copy.deepcopy(load_model("five-link").to_dict())
    data["name"] = "weak"
    for a in data["actuators"]:
        a["limits"] = [-5.0, 5.0]
    return model_from_dict(data)


def test_infeasible_torque_bounds_are_named() -> None:
    solution = solve_gait_solution(_weak_biped(), GaitOptions.paper(continuation=False))
    assert not solution.success
    text = diagnose(solution).text()
    assert "torque knee_1 at its bound (-5, 5 N m)" in text
    assert "looser torque bounds" in text


def test_a_step_too_fast_for_the_legs_says_which_torques_saturate(tmp_path) -> None:  # noqa: ANN001
    """The example of the issue: 80 m/min with 0.75 m steps. Today's message named the
    motion between knots; the real obstacle is the torque bounds at every knot."""
    out = tmp_path / "fast.gait.json"
    result = CliRunner(env={"COLUMNS": "200"}).invoke(
        cli, ["solve", "--speed", "80m/min", "--step-length", "0.75", "-o", str(out)])
    assert result.exit_code == 1, result.output
    text = " ".join(result.output.split())
    assert "between knots" not in text
    assert "torque hip_1 at its bound (-50, 50 N m)" in text
    assert "looser torque bounds" in text and "No gait file written" in text
    assert not out.exists()
