"""Stage ``warm start`` from a solution of the same NLP on the same grid, with its multipliers
(a gait file's point, a sweep's neighbour), is solved with IPOPT's adaptive barrier first
(``gaitopt.gait.solve.stages.RESTART_OPTIONS``) and, where that does not converge within
``RESTART_MAX_ITER`` iterations, again from the same start with the monotone barrier: either
way to the optimum the monotone barrier alone finds. A start without multipliers (a file's
trajectories) is solved once, as before."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from gaitopt.gait.api import guess_from_gait, restart_point
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve import stages
from gaitopt.gait.solve.staged import solve_walking
from gaitopt.ocp import Transcription, WarmStart
from gaitopt.robot import RobotModel, load_model


@pytest.fixture(scope="module")
def model() -> RobotModel:
    return load_model("five-link")


@pytest.fixture(scope="module")
def faster(model: RobotModel) -> GaitOptions:
    """The default gait's problem at 0.21 m/s (the file's 0.2 m/s + 5 %)."""
    return options_for_model(model, GaitOptions.paper(speed=0.21))


@pytest.fixture(scope="module")
def start(model: RobotModel, faster: GaitOptions, default_gait_file: Path) -> WarmStart:
    point = restart_point(model, faster, Gait.load(default_gait_file))
    assert point is not None
    return point


@pytest.fixture
def barriers(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[str]]:
    """The barrier strategy IPOPT was given, per solve of a stage, in order."""
    seen: list[str] = []
    solve = Transcription.solve

    def recording(self: Transcription, *args: Any, **kwargs: Any) -> Any:
        given = {**(kwargs.get("options") or {}), **(kwargs.get("warm_start_options") or {})}
        seen.append(str(given.get("ipopt.mu_strategy", "monotone")))
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(Transcription, "solve", recording)
    yield seen


def test_a_restart_takes_the_adaptive_barrier_to_the_monotone_optimum(
        model: RobotModel, faster: GaitOptions, start: WarmStart,
        barriers: list[str]) -> None:
    adaptive = solve_walking(model, faster, warm_start=start, adaptive_restart=True)
    monotone = solve_walking(model, faster, warm_start=start, adaptive_restart=False)
    assert barriers == ["adaptive", "monotone"]
    assert [s.name for s in adaptive.stages] == ["warm start"] == [s.name for s in
                                                                    monotone.stages]
    assert adaptive.success and monotone.success
    assert adaptive.result.objective == pytest.approx(monotone.result.objective, rel=1e-6)
    assert adaptive.stages[0].iterations <= stages.RESTART_MAX_ITER


def test_a_restart_that_does_not_converge_is_solved_again_with_the_monotone_barrier(
        model: RobotModel, faster: GaitOptions, start: WarmStart, barriers: list[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(stages, "RESTART_MAX_ITER", 2)
    run = solve_walking(model, faster, warm_start=start, adaptive_restart=True)
    first, again = run.stages
    assert barriers == ["adaptive", "monotone"]
    assert (first.name, first.success, first.iterations) == ("warm start", False, 2)
    assert first.status == "Maximum_Iterations_Exceeded"
    assert again.name == "warm start, monotone barrier" and again.success
    monotone = solve_walking(model, faster, warm_start=start, adaptive_restart=False)
    assert run.success
    assert run.result.objective == pytest.approx(monotone.result.objective, rel=1e-9)


def test_the_user_iteration_limit_bounds_the_adaptive_attempt(faster: GaitOptions) -> None:
    assert stages.restart_options(faster)["ipopt.max_iter"] == stages.RESTART_MAX_ITER
    assert stages.restart_options(faster.replace(max_iter=5))["ipopt.max_iter"] == 5


def test_a_start_without_multipliers_is_solved_once(
        model: RobotModel, faster: GaitOptions, default_gait_file: Path,
        barriers: list[str]) -> None:
    run = solve_walking(model, faster, warm_start=guess_from_gait(Gait.load(default_gait_file)),
                        adaptive_restart=True)
    assert barriers[0] == "monotone" and run.stages[0].name == "warm start"
    assert "warm start, monotone barrier" not in [s.name for s in run.stages]


def test_a_file_restarts_with_the_adaptive_barrier_only_for_its_own_problem(
        model: RobotModel, default_gait_file: Path, barriers: list[str]) -> None:
    """``solve_gait`` from a file: the adaptive barrier where the file solved the same
    problem at another speed; the monotone one at the file's own speed (it confirms the
    file's point) and from the file of another cost (there the adaptive restart did not
    converge in the cost study)."""
    from gaitopt.gait.api import solve_gait

    gait = Gait.load(default_gait_file)
    same = solve_gait(model, GaitOptions.paper(speed=0.21), warm_start=gait)
    assert barriers == ["adaptive"] and same.success
    barriers.clear()
    own = solve_gait(model, GaitOptions.paper(speed=gait.options["speed"]), warm_start=gait)
    assert barriers == ["monotone"] and own.success  # the file's own problem: confirmed
    barriers.clear()
    work = GaitOptions.paper(speed=0.21, cost="work")
    assert restart_point(model, options_for_model(model, work), gait) is not None
    other = solve_gait(model, work, warm_start=gait)
    assert barriers[0] == "monotone"
    assert other.solver["stages"][0]["name"] == stages.WARM_START_STAGE
