"""Failures that explain themselves: at the best point a failed solve found, which
constraints are violated or binding, in words and numbers, and what the user can change.

A grid too coarse for the motion does not make the NLP fail (3 + 2 knots converge at 12 and
60 m/min); it shows as a converged solution whose motion leaves a leg's reach between knots,
which is refused with advice to use a finer grid (tests/gait/test_walking_errors.py and
tests/gait/test_cli_gait.py)."""

from __future__ import annotations

import copy
import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.api import solve_gait, solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError
from gaitopt.gait.solve.diagnose import diagnose
from gaitopt.gait.solve.staged import StagedRun, transcription_for
from gaitopt.robot import load_model, model_from_dict, model_to_yaml
from tests.gait.conftest import Solved


def _weak_biped() -> object:
    """The five-link model with every torque bound at 5 N m: too weak to walk (a bent knee
    under the body's weight alone needs tens of N m)."""
    data = copy.deepcopy(load_model("five-link").to_dict())
    data["name"] = "weak"
    for a in data["actuators"]:
        a["limits"] = [-5.0, 5.0]
    return model_from_dict(data)


def test_infeasible_torque_bounds_are_named() -> None:
    solution = solve_staged_run(_weak_biped(), GaitOptions.paper(continuation=False))
    assert not solution.success
    diagnosis = diagnose(solution)
    text = diagnosis.text()
    assert "torque knee_1 at its bound (-5, 5 N m)" in text
    assert "looser torque bounds" in text
    assert diagnosis.cause.startswith("the torque bounds: ")
    assert diagnosis.advice[0].startswith("the torques saturate")


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
    # The cause is named first, then the constraint with the largest violation.
    assert "Most likely cause: the torque bounds: hip_1 at the bound at" in text
    assert re.search(r"Largest violation: '[^']+' violated by [0-9.e+-]+\.", text)
    # The violation reported is the diagnosed stage's (its own progress line), not the last
    # stage's (the continuation from 12 m/min, far worse).
    stage = re.search(r"the solve failed at stage '([^']+)'", text).group(1)  # type: ignore[union-attr]
    line = next(ln for ln in result.output.splitlines() if f"stage {stage} " in ln
                and "80.00 m/min" in ln and "FAILED" in ln)
    stage_violation = float(re.search(r"viol (\S+)", line).group(1))  # type: ignore[union-attr]
    reported = float(re.search(r"Largest constraint violation at that point (\S+)",
                               text).group(1))  # type: ignore[union-attr]
    assert reported == pytest.approx(stage_violation, rel=0.05)
    # Each piece of advice once, however many phases show the same kind of violation.
    lines = result.output.splitlines()
    first = next(i for i, ln in enumerate(lines) if ln.startswith("What you can change"))
    advice = [ln for ln in lines[first + 1:] if ln.startswith("  - ")]
    assert advice and len(advice) == len(set(advice))


def _failed_at(solution: StagedRun, state: str, value: float) -> StagedRun:
    """``solution`` marked failed at its last stage, with ``state`` at ``value`` at every
    knot of every phase (the NLP point itself is unchanged: no constraint is violated)."""
    res = solution.result
    phases = []
    for traj in res.phases:
        if state in traj.states:
            x = np.array(traj.x, copy=True)
            x[:, traj.states.index(state)] = value
            traj = dataclasses.replace(traj, x=x)
        phases.append(traj)
    failed = dataclasses.replace(res, success=False, status="Infeasible_Problem_Detected",
                                 phases=tuple(phases))
    return dataclasses.replace(solution, result=failed,
                               stage_results=(("enforced contact", failed),))


def test_legs_at_full_reach_alone_are_listed_but_no_cause(default_solved: Solved) -> None:
    """The optimal walk itself keeps the stance knee at its least bend (r at its longest) at
    most knots, so r at its bound is listed, never the cause by itself."""
    solution = default_solved.solution
    tr = transcription_for(solution.model, solution.options, solution.options.knots)
    single = tr.problem.phases[0]
    r_max = float(single.state_bounds["r"][1])
    diagnosis = diagnose(_failed_at(solution, "r", r_max))
    knots = sum(ph.t.size for ph in solution.result.phases)
    assert any("hip-to-tip distance r at its bound" in f and f"at {knots} of {knots} knots" in f
               for f in diagnosis.findings)
    assert diagnosis.largest == ""  # the NLP point is the converged one: nothing violated
    assert diagnosis.cause == ""
    assert not any("shorter step" in a for a in diagnosis.advice)


def test_torques_at_their_bounds_at_most_knots_are_the_cause(default_solved: Solved) -> None:
    solution = default_solved.solution
    knee = solution.model.actuators[solution.model.actuator_index("knee_1")]
    res = solution.result
    single = res.phases[0]
    u = np.array(single.u, copy=True)
    u[:, single.controls.index("knee_1")] = knee.limits[1]
    failed = dataclasses.replace(res, success=False, status="Infeasible_Problem_Detected",
                                 phases=(dataclasses.replace(single, u=u), *res.phases[1:]))
    diagnosis = diagnose(dataclasses.replace(solution, result=failed,
                                             stage_results=(("enforced contact", failed),)))
    knots = sum(ph.t.size for ph in res.phases if "knee_1" in ph.controls)
    assert diagnosis.cause == (f"the torque bounds: knee_1 at the bound at {single.t.size} of "
                               f"{knots} knots")
    assert diagnosis.advice[0].startswith("the torques saturate")


def _short_legs(tmp_path: Path, length: float = 0.2) -> Path:
    """The five-link model with thighs and shanks ``length`` m long (reach about 2 length)."""
    data = copy.deepcopy(load_model("five-link").to_dict())
    data["name"] = "short-legs"
    for link in data["links"][1:]:
        link.update(length=length, com=[length / 2, 0.0])
        link.pop("inertia")  # from the shape again
        if link["joint"]["name"].startswith("knee"):
            link["joint"]["at"] = [length, 0.0]
    for contact in data["contacts"]:
        contact["at"] = [length, 0.0]
    path = tmp_path / "short-legs.yaml"
    path.write_text(model_to_yaml(model_from_dict(data)))
    return path


@pytest.mark.parametrize(("step", "words"), [
    ("0.78", "longer than the legs can reach"),  # refused by the options' own check
    # The step bounds follow the model (0.8 leg lengths: 0.32 m on 0.4 m legs): a step
    # beyond them is refused by name before the reach is looked at.
    ("0.7", "must lie in targets.step_length_bounds [0.008, 0.32] m"),
])
def test_an_unreachable_step_is_one_line_naming_the_reach(tmp_path: Path, step: str,
                                                          words: str) -> None:
    out = tmp_path / "x.gait.json"
    result = CliRunner().invoke(cli, ["solve", "--model", str(_short_legs(tmp_path)),
                                      "--step-length", step, "-o", str(out)])
    assert result.exit_code == 2, result.output
    last = result.output.strip().splitlines()[-1]  # after the "solving ..." line, if any
    assert last.startswith("Error: targets.step_length = ") and words in last
    assert ("shorter step" in last or "needs step_length <" in last
            or "step_length_bounds" in last)
    assert "Traceback" not in result.output and not out.exists()


def test_a_step_no_naive_start_can_place_is_one_line_naming_the_reach(tmp_path: Path) -> None:
    """With the step bounds widened past the legs (0.7 m on 0.4 m legs), no naive start
    places the legs: the refusal says so and what to change."""
    options = GaitOptions(step_length=0.7, step_length_bounds=(0.02, 0.8))
    with pytest.raises(GaitOptionsError) as info:
        solve_gait(str(_short_legs(tmp_path)), options)
    message = str(info.value)
    assert message.startswith("targets.step_length = ")
    assert "every naive start puts a leg beyond its reach" in message
    assert "shorter step" in message or "needs step_length <" in message
