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


def finer(model: RobotModel, warm: SavedGait) -> PointTask:
    """The point of ``task`` on 24 + 8 knots (the file solved 16 + 6)."""
    return PointTask(key="k", model=model,
                     options=options_for_model(model, GaitOptions(speed=0.3, knots=(24, 8))),
                     variant="ankle+impulse", speed_mode="fixed", structure="s", warm=warm,
                     relfile="k.gait.json")


def test_a_file_of_another_grid_starts_the_point_with_its_multipliers_mapped(
        five_link: RobotModel, saved: SavedGait) -> None:
    """The file's point and multipliers mapped onto the point's grid (the study's check and
    refinement sweeps): a start with multipliers, not the file's values alone; mapped onto
    the file's own grid it is the file's point again."""
    from gaitopt.gait.api import regridded_point, restart_point
    from gaitopt.gait.record.file import Gait
    from gaitopt.gait.solve.warm_accuracy import stored_point
    from gaitopt.ocp import WarmStart
    from gaitopt.study.worker import REGRIDDED

    point, how, _ = _warm_start(finer(five_link, saved))
    assert how == REGRIDDED and isinstance(point, WarmStart)
    assert np.all(np.isfinite(point.lam_g)) and np.any(point.lam_g != 0.0)

    gait = Gait.from_dict(json.loads(saved.text))
    own = regridded_point(five_link, options(five_link), gait)
    kept = stored_point(gait.solver["warm_start"])
    assert own is not None and kept is not None
    assert restart_point(five_link, options(five_link), gait) is not None  # the same grid
    np.testing.assert_allclose(own.w, kept.w, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(own.lam_g, kept.lam_g, rtol=1e-6, atol=1e-9)

    without = json.loads(saved.text)
    del without["solver"]["warm_start"]  # a file written before it kept its point
    assert regridded_point(five_link, finer(five_link, saved).options,
                           Gait.from_dict(without)) is None


def adaptive_restarts(monkeypatch: pytest.MonkeyPatch) -> list[bool]:
    """The ``adaptive_restart`` of every ``solve_walking`` call of the worker, in order."""
    from gaitopt.gait.solve import staged

    given: list[bool] = []
    solve_walking = staged.solve_walking

    def recording(*args: object, **kwargs: object) -> object:
        given.append(bool(kwargs.get("adaptive_restart", False)))
        return solve_walking(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr("gaitopt.study.worker.solve_walking", recording)
    return given


def test_a_point_started_from_a_file_of_another_grid_reaches_the_cold_optimum(
        five_link: RobotModel, saved: SavedGait, monkeypatch: pytest.MonkeyPatch) -> None:
    """... with the monotone barrier only: the adaptive barrier of a same-grid restart
    (``solve_walking(adaptive_restart=...)``) is not tried on a start mapped from another
    grid."""
    given = adaptive_restarts(monkeypatch)
    outcome = solve_point(finer(five_link, saved))
    cold = solve_gait(five_link, finer(five_link, saved).options)
    assert outcome.gait is not None and outcome.warm == "file, regridded"
    assert given == [False]
    assert [s["name"] for s in outcome.gait["solver"]["stages"]][0] == "warm start"
    assert outcome.gait["cost"]["value"] == pytest.approx(cold.cost_value, rel=1e-5)


def test_a_chain_point_starts_from_the_secant_through_the_two_before(
        five_link: RobotModel, monkeypatch: pytest.MonkeyPatch) -> None:
    """With the chain's last two Results (``PointTask.secant``) a point starts from their
    secant prediction (values and multipliers), reaches the optimum the last Result alone
    reaches, and falls back to that Result where the two are of different grids. The
    secant start is solved with the monotone barrier only (``worker.MONOTONE_STARTS``)."""
    from gaitopt.gait.solve.staged import solve_walking
    from gaitopt.ocp import WarmStart

    def at(speed: float, knots: tuple[int, int] = (16, 6)) -> GaitOptions:
        return options_for_model(five_link, GaitOptions(speed=speed, knots=knots))

    first = solve_walking(five_link, at(0.2)).result
    last = solve_walking(five_link, at(0.3), warm_start=first).result
    assert first.success and last.success

    def point(secant: tuple[object, float] | None) -> PointTask:
        return PointTask(key="k", model=five_link, options=at(0.45), variant="ankle+impulse",
                         speed_mode="fixed", structure="s", warm=last, relfile="k.gait.json",
                         secant=secant)  # type: ignore[arg-type]

    start, how, _ = _warm_start(point((first, 1.5)))
    assert how == "result, secant" and isinstance(start, WarmStart)
    np.testing.assert_allclose(start.w, last.w + 1.5 * (last.w - first.w))
    np.testing.assert_allclose(start.lam_g, last.lam_g + 1.5 * (last.lam_g - first.lam_g))
    given = adaptive_restarts(monkeypatch)
    secant, alone = solve_point(point((first, 1.5))), solve_point(point(None))
    assert given == [False, True]  # the adaptive barrier for the Result as it is only
    assert secant.success and alone.success and alone.warm == "result"
    assert secant.row.cost == pytest.approx(alone.row.cost, rel=1e-6)
    other = solve_walking(five_link, at(0.2, (24, 8))).result
    assert _warm_start(point((other, 1.5)))[1] == "result"


def test_a_cold_point_leaves_its_check_grid_to_the_sweep_where_asked(
        five_link: RobotModel) -> None:
    """``PointTask.check_cold`` (``SweepSpec.check_cold``): a cold point solves its check grid
    for the estimate by default; without it the same answer comes without that stage."""

    def cold(check_cold: bool) -> PointTask:
        return PointTask(key="k", model=five_link, options=options(five_link),
                         variant="ankle+impulse", speed_mode="fixed", structure="s", warm=None,
                         relfile="k.gait.json", check_cold=check_cold)

    checked, unchecked = solve_point(cold(True)), solve_point(cold(False))
    assert checked.gait is not None and unchecked.gait is not None
    assert checked.warm == unchecked.warm == "none"
    names = [[s["name"] for s in o.gait["solver"]["stages"]] for o in (checked, unchecked)]
    assert "check grid" in names[0] and not any("check grid" in n for n in names[1])
    assert names[1] == [n for n in names[0] if "check grid" not in n]
    assert unchecked.row.cost == checked.row.cost
    assert checked.gait["solver"]["accuracy"]["check_cost"] is not None
    assert unchecked.gait["solver"]["accuracy"]["check_cost"] is None


def test_a_restart_solved_again_with_the_monotone_barrier_did_not_fall_back(
        five_link: RobotModel, monkeypatch: pytest.MonkeyPatch) -> None:
    """A point restarted from its neighbour's Result (``worker.ADAPTIVE_STARTS``) whose
    adaptive restart stopped at its iteration bound and whose monotone restart converged is
    a warm start (``fell_back`` False: the sweep's line does not say ``-> cold``), at the
    optimum the adaptive restart reaches. A start from a file takes the monotone barrier
    only."""
    from gaitopt.gait.solve import stages
    from gaitopt.gait.solve.staged import solve_walking

    neighbour = solve_walking(five_link, options(five_link)).result
    assert neighbour.success
    faster = PointTask(key="k", model=five_link,
                       options=options_for_model(five_link, GaitOptions(speed=0.33,
                                                                        knots=(16, 6))),
                       variant="ankle+impulse", speed_mode="fixed", structure="s",
                       warm=neighbour, relfile="k.gait.json")
    given = adaptive_restarts(monkeypatch)
    adaptive = solve_point(faster)
    monkeypatch.setattr(stages, "RESTART_MAX_ITER", 2)
    again = solve_point(faster)
    assert given == [True, True]
    assert adaptive.gait is not None and again.gait is not None
    assert adaptive.warm == again.warm == "result"
    names = [[s["name"] for s in o.gait["solver"]["stages"]] for o in (adaptive, again)]
    assert names == [[stages.WARM_START_STAGE],
                     [stages.WARM_START_STAGE, stages.MONOTONE_RESTART_STAGE]]
    assert not adaptive.fell_back and not again.fell_back
    assert again.row.cost == pytest.approx(adaptive.row.cost, rel=1e-6)


def test_a_point_from_a_file_of_its_grid_takes_the_monotone_barrier(
        five_link: RobotModel, saved: SavedGait, monkeypatch: pytest.MonkeyPatch) -> None:
    given = adaptive_restarts(monkeypatch)
    outcome = solve_point(task(five_link, saved, check_grid=False))
    assert outcome.warm == "file" and given == [False]
