"""How the stages on finer grids start and stop (docs/walking.md, section "Stages"):

* the held stage (step length and speed held at the coarse solution's) is solved to
  :data:`gaitopt.gait.solve.stages.HELD_STAGE_TOL` when its release follows: it is only the
  release's start. The answer must not change, and a held stage that is the answer keeps
  the user's tolerance;
* the walk's check grid starts its barrier at 1e-8
  (:data:`~gaitopt.gait.solve.stages.CHECK_GRID_OPTIONS`): its cost must be the one a start at
  1e-6 reaches, within the solve's accuracy;
* a check grid started from the target grid's solution mapped with its multipliers (the
  heel-toe walk's move; here made the five-link walk's) is bounded at
  :data:`~gaitopt.gait.solve.stages.CHECK_REGRID_MAX_ITER` iterations, and where it does not
  converge the check grid is solved from the values only (stage ``check grid, from
  values``), to the check cost of that start, which the answer's estimate then uses."""

from __future__ import annotations

from typing import Any

import pytest

from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve import staged, stages
from gaitopt.gait.solve.accuracy import accuracy_record
from gaitopt.gait.solve.staged_run import CHECK_FROM_VALUES_STAGE, StagedRun, check_result
from gaitopt.gait.solve.stages import CHECK_GRID_OPTIONS, HELD_STAGE_TOL, held_stage_options
from gaitopt.ocp import Transcription
from gaitopt.robot import load_model

COARSE = (8, 5)


def _fine_tolerances(monkeypatch: pytest.MonkeyPatch, options: GaitOptions
                     ) -> tuple[list[Any], float]:
    """Solve ``options``; the ``ipopt.tol`` given to each IPOPT call on a grid finer than the
    coarse one, in order (None: the transcription's, the user's ``tol``), and the answer's
    cost."""
    given, solution = _fine_calls(monkeypatch, options, "ipopt.tol")
    return given, solution.result.objective


def _fine_calls(monkeypatch: pytest.MonkeyPatch, options: GaitOptions, key: str
                ) -> tuple[list[Any], StagedRun]:
    """Solve ``options``; the option ``key`` given to each IPOPT call on a grid finer than the
    coarse one, in order (None: not given), and the solution."""
    given: list[Any] = []
    original = Transcription.solve

    def recording(self: Transcription, *args: Any, **kwargs: Any) -> Any:
        if tuple(m.size for m in self.mesh) != COARSE:
            given.append((kwargs.get("options") or {}).get(key))
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Transcription, "solve", recording)
    solution = solve_staged_run(load_model("five-link"), options)
    assert solution.success
    return given, solution


def test_the_held_stage_before_a_release_stops_early_and_the_answer_is_unchanged(
        monkeypatch: pytest.MonkeyPatch) -> None:
    options = GaitOptions(knots=(16, 6), speed=0.4)
    given, cost = _fine_tolerances(monkeypatch, options)
    # the held target grid, its release, the check grid
    assert given == [HELD_STAGE_TOL, None, None]
    # the same solve with the held stage solved to the user's tolerance
    monkeypatch.setattr(stages, "HELD_STAGE_TOL", 0.0)
    strict, strict_cost = _fine_tolerances(monkeypatch, options)
    assert strict == [options.tol, None, None]
    assert cost == pytest.approx(strict_cost, rel=1e-5)


def test_a_held_stage_that_is_the_answer_keeps_the_users_tolerance(
        monkeypatch: pytest.MonkeyPatch) -> None:
    given, _ = _fine_tolerances(monkeypatch, GaitOptions(knots=(16, 6), speed=0.4,
                                                         step_length=0.3))
    assert given == [None, None]  # the target grid (nothing to release), the check grid


def test_a_looser_user_tolerance_wins() -> None:
    assert held_stage_options(GaitOptions(tol=1e-4), released=True)["ipopt.tol"] == 1e-4
    assert held_stage_options(GaitOptions(), released=True)["ipopt.tol"] == HELD_STAGE_TOL
    assert "ipopt.tol" not in held_stage_options(GaitOptions(), released=False)


def _check_cost(solution: StagedRun) -> float:
    (check,) = [s for s in solution.stages if s.name == "check grid"]
    assert check.success
    return check.objective


def test_the_check_grid_starts_at_a_small_barrier_and_reaches_the_same_cost(
        monkeypatch: pytest.MonkeyPatch) -> None:
    options = GaitOptions(knots=(16, 6), speed=0.6)
    given, solution = _fine_calls(monkeypatch, options, "ipopt.mu_init")
    assert given[-1] == CHECK_GRID_OPTIONS["ipopt.mu_init"] == 1e-8
    monkeypatch.setitem(CHECK_GRID_OPTIONS, "ipopt.mu_init", 1e-6)
    given, before = _fine_calls(monkeypatch, options, "ipopt.mu_init")
    assert given[-1] == 1e-6
    assert solution.result.objective == pytest.approx(before.result.objective, rel=1e-10)
    # the check costs agree within 10 x the solves' accuracy (about 1e-6 against a tight solve)
    assert _check_cost(solution) == pytest.approx(_check_cost(before), rel=1e-5)


def test_a_mapped_check_grid_start_is_bounded_and_falls_back_to_the_values(
        monkeypatch: pytest.MonkeyPatch) -> None:
    options = GaitOptions(knots=(16, 6), speed=0.4)
    plain = solve_staged_run(load_model("five-link"), options)  # the check from the values
    assert plain.success and [s.name for s in plain.stages][-1] == "check grid"
    monkeypatch.setattr(staged, "REGRID_MOVES", {"walk": frozenset({"check"})})
    bounds, mapped = _fine_calls(monkeypatch, options, "ipopt.max_iter")
    names = [s.name for s in mapped.stages]
    assert names[-1] == "check grid" and CHECK_FROM_VALUES_STAGE not in names
    assert bounds[-1] == stages.CHECK_REGRID_MAX_ITER  # the mapped start, bounded
    assert mapped.stages[-1].iterations <= stages.CHECK_REGRID_MAX_ITER
    # a mapped start that does not converge within the bound: the values-only check after it
    monkeypatch.setattr(staged, "CHECK_REGRID_MAX_ITER", 1)
    bounds, fallen = _fine_calls(monkeypatch, options, "ipopt.max_iter")
    last = fallen.stages[-2:]
    assert [s.name for s in last] == ["check grid", CHECK_FROM_VALUES_STAGE]
    assert not last[0].success and last[1].success and bounds[-2:] == [1, None]
    checked = check_result(fallen)
    assert checked is not None and checked.objective == pytest.approx(last[1].objective)
    assert checked.objective == pytest.approx(check_result(plain).objective, rel=1e-6)
    assert fallen.result.objective == pytest.approx(plain.result.objective, rel=1e-9)
    estimate = accuracy_record(fallen)["cost_error"]
    assert estimate == pytest.approx(accuracy_record(plain)["cost_error"], rel=1e-3, abs=1e-6)
