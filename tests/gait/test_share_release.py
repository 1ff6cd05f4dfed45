"""Phase shares released (gait.solve.share_release): which solves release them, the free
problem first and kept without the fixed-share solve where it wins on the coarse grid, the
decision between the fixed-share and the released optimum on fake runs, the released run's
record, the plausibility check on a real gait, and (slow) the seven-link default solves."""

from __future__ import annotations

import dataclasses
import math
import re
from types import SimpleNamespace
from typing import Any

import pytest

from gaitopt.analysis.plausible import Verifier, verified
from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.formulations.select import contact_sequence
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.solve.record import gait_from_run
from gaitopt.gait.solve.share_release import (
    FREEING_STAGE,
    PREFIX,
    SAME_COST,
    coarse_release,
    decision,
    release_first,
    release_shares,
    releases_shares,
    shares_of,
)
from gaitopt.gait.solve.staged_run import StageRecord
from gaitopt.robot import RobotModel, load_model
from tests.gait.conftest import SolveFn


def _resolved(model: RobotModel, **changes: Any) -> GaitOptions:
    return options_for_model(model, GaitOptions(**changes))


def test_only_a_built_in_sequence_of_more_than_two_phases_releases(
        seven: RobotModel, five: RobotModel) -> None:
    heel_toe = _resolved(seven)
    assert heel_toe.gait == "heel-toe" and heel_toe.free_phase_fractions is None
    assert releases_shares(seven, heel_toe)
    # The two-phase walk's single-support share is the problem's datum: fixed (the five-link
    # default, in either formulation), and so is a run's stance share (already free).
    assert not releases_shares(five, _resolved(five))
    assert not releases_shares(five, _resolved(five, formulation="full"))
    assert not releases_shares(seven, _resolved(seven, gait="run"))
    # Shares the caller decided: fixed, free from the start, a sequence given, a stride.
    assert not releases_shares(seven, heel_toe.replace(free_phase_fractions=False))
    assert not releases_shares(seven, heel_toe.replace(free_phase_fractions=True))
    given = contact_sequence(seven, heel_toe).to_dict()
    assert not releases_shares(seven, heel_toe.replace(contact_sequence=given))
    assert not releases_shares(seven, heel_toe.replace(stride=True))


@dataclasses.dataclass(frozen=True)
class _Run:
    """What decision() and release_shares() read of a StagedRun."""

    model: Any
    options: Any
    success: bool
    failed_stage: Any
    result: Any
    accuracy_extra: Any
    wall_time_s: float
    stages: tuple[Any, ...]
    share_release: Any = None


def _fake_run(model: RobotModel, options: GaitOptions, shares: tuple[float, ...], cost: float,
              *, success: bool = True, within: bool | None = True, wall: float = 1.0,
              stages: tuple[Any, ...] = ()) -> Any:
    """A run of a 1.5 s step in ``shares`` costing ``cost``."""
    phases = tuple(SimpleNamespace(duration=1.5 * s) for s in shares)
    failed = None if success else SimpleNamespace(name="warm start", status="Maximum_Iterations")
    return _Run(model=model, options=options, success=success, failed_stage=failed,
                result=SimpleNamespace(objective=cost, phases=phases),
                accuracy_extra={"within_target": within}, wall_time_s=wall, stages=stages)


FIXED_SHARES = (0.425, 0.2975, 0.15, 0.1275)
FREE_SHARES = (0.414, 0.149, 0.241, 0.196)


@pytest.mark.parametrize(("free_changes", "plausible", "released", "why"), [
    ({}, None, True, r"the free shares cost 40.0 % less: released"),
    ({"success": False}, None, False, r"free-share solve failed \(stage warm start: "
                                      r"Maximum_Iterations\)"),
    ({"within": False}, None, False, "not converged to the accuracy"),
    ({"cost": 3000.0 * (1 - SAME_COST / 2)}, None, False, "cost no less"),
    ({"cost": 3100.0}, None, False, r"cost no less \(\+3.33 %\)"),
    ({}, "verify fails swing.reversals (6 > 3 turns)", False,
     r"not plausible: verify fails swing.reversals \(6 > 3 turns\); the fixed shares kept"),
])
def test_the_decision_keeps_the_free_optimum_only_where_lower_converged_and_plausible(
        seven: RobotModel, free_changes: dict[str, Any], plausible: str | None,
        released: bool, why: str) -> None:
    options = _resolved(seven)
    fixed = _fake_run(seven, options, FIXED_SHARES, 3000.0)
    free = _fake_run(seven, options.replace(free_phase_fractions=True), FREE_SHARES,
                     **{"cost": 1800.0, **free_changes})
    seen: list[Any] = []

    def check(run: Any) -> str | None:
        seen.append(run)
        return plausible

    out = decision(fixed, free, check)
    assert out["released"] is released
    assert re.search(why, out["why"])
    assert out["fixed_cost"] == 3000.0
    assert out["fixed_shares"] == pytest.approx(FIXED_SHARES, abs=1e-12)
    if free_changes.get("success", True):
        assert out["free_shares"] == pytest.approx(FREE_SHARES, abs=1e-12)
        assert math.fsum(out["free_shares"]) == pytest.approx(1.0, abs=1e-12)
    else:
        assert out["free_cost"] is None and out["free_shares"] is None
    # The plausibility check judges only a lower, converged optimum (it costs a verify).
    assert seen == ([free] if released or plausible is not None else [])


def test_a_fixed_solve_short_of_its_accuracy_may_be_replaced_by_a_converged_free_one(
        seven: RobotModel) -> None:
    options = _resolved(seven)
    fixed = _fake_run(seven, options, FIXED_SHARES, 3000.0, within=False)
    free = _fake_run(seven, options, FREE_SHARES, 2000.0, within=False)
    assert decision(fixed, free)["released"]


def test_the_release_solves_the_free_problem_on_the_fixed_grid_and_keeps_every_stage(
        seven: RobotModel) -> None:
    options = _resolved(seven).replace(knots=(36, 26, 24, 24))
    stage = StageRecord(name="check grid", knots=(36, 26, 24, 24), status="Solve_Succeeded",
                        success=True, iterations=30, objective=1.0, violation=0.0,
                        wall_time_s=1.0, parameters={})
    fixed = _fake_run(seven, options, FIXED_SHARES, 3000.0, wall=100.0, stages=(stage,))
    asked: list[GaitOptions] = []

    def solve_free(free_options: GaitOptions, start: Any) -> Any:
        asked.append(free_options)
        assert start is fixed
        named = dataclasses.replace(stage, name=PREFIX + "warm start")
        return _fake_run(seven, free_options, FREE_SHARES, 2000.0, wall=40.0, stages=(named,))

    for check, kept in ((lambda run: None, "free"), (lambda run: "flaps", "fixed")):
        asked.clear()
        run = release_shares(fixed, solve_free, check)
        (free_options,) = asked
        assert free_options.free_phase_fractions is True and free_options.phase_shares is None
        assert tuple(free_options.knots) == (36, 26, 24, 24)
        assert run.share_release["released"] is (kept == "free")
        assert run.result.objective == (2000.0 if kept == "free" else 3000.0)
        assert [s.name for s in run.stages] == ["check grid", PREFIX + "warm start"]
        assert run.wall_time_s == pytest.approx(140.0)


def test_shares_of_a_real_solve_sum_to_one_and_match_its_phases(solved: SolveFn) -> None:
    run = solved().solution
    shares = shares_of(run)
    assert math.fsum(shares) == pytest.approx(1.0, abs=1e-9)
    assert shares[0] == pytest.approx(run.options.single_support_fraction, abs=1e-9)


def test_the_plausibility_check_is_verify(solved: SolveFn) -> None:
    run = solved().solution
    assert verify_gait(gait_from_run(run)).passed
    assert verified(run) is None
    # A gait verify rejects: the same run with its cost changed (cost.recomputed fails).
    bad = dataclasses.replace(run, result=dataclasses.replace(
        run.result, objective=run.result.objective * 1.5))
    why = verified(bad)
    assert why is not None and why.startswith("verify fails cost.recomputed (")


def test_without_a_plausibility_check_the_shares_stay_fixed(monkeypatch: pytest.MonkeyPatch,
                                                           seven: RobotModel) -> None:
    """solve_staged_run releases only with a check: the fixed-share run is the answer; with
    one, the free problem is solved first and, where release_first does not keep it, the
    fixed-share run follows and release_shares decides."""
    import gaitopt.gait.api as api

    calls: list[Any] = []
    fixed = SimpleNamespace(success=True, options=_resolved(seven), accuracy_extra=None)
    own = SimpleNamespace(success=False, options=_resolved(seven))
    monkeypatch.setattr(api, "solve_walking", lambda *a, **k: fixed)
    monkeypatch.setattr(api, "_own_release", lambda *a, **k: calls.append("own") or own)
    monkeypatch.setattr(api, "refine_to_accuracy", lambda run, **k: (run, {}))
    monkeypatch.setattr(api, "release_shares",
                        lambda *a, **k: calls.append(("release", k["first"])) or a[0])
    monkeypatch.setattr(api, "refuse_unwalkable", lambda *a, **k: None)
    assert solve_staged_run(seven, GaitOptions()) is fixed and calls == []
    assert solve_staged_run(seven, GaitOptions(), plausible=lambda run: None) is fixed
    assert calls == ["own", ("release", own)]
    # a fixed solve at another speed (the slower default) does not reuse the free run
    calls.clear()
    fixed.options = fixed.options.replace(speed=0.2)
    assert solve_staged_run(seven, GaitOptions(), plausible=lambda run: None) is fixed
    assert calls == ["own", ("release", None)]


def _stage(name: str, objective: float, success: bool = True,
           knots: tuple[int, ...] = (8, 5, 5, 5)) -> StageRecord:
    return StageRecord(name=PREFIX + name, knots=knots, status="Solve_Succeeded",
                       success=success, iterations=10, objective=objective, violation=0.0,
                       wall_time_s=1.0, parameters={})


COARSE = (_stage("enforced contact", 2888.0), _stage("liftoff impulse free", 2313.0),
          _stage(FREEING_STAGE, 1617.0), _stage("target grid", 1656.0, knots=(24, 18, 16, 16)))


def test_the_free_problem_first_is_kept_where_it_wins_on_the_coarse_grid(
        seven: RobotModel) -> None:
    options = _resolved(seven).replace(free_phase_fractions=True)
    free = _fake_run(seven, options, FREE_SHARES, 1655.8, stages=COARSE)
    assert coarse_release(free) == (2313.0, 1617.0, (8, 5, 5, 5))
    seen: list[Any] = []
    out = release_first(free, seven, lambda run: seen.append(run) or None)
    assert out is not None and seen == [free]
    assert out["released"] is True and out["fixed_cost"] == 2313.0
    assert out["fixed_knots"] == [8, 5, 5, 5] and out["coarse_free_cost"] == 1617.0
    assert out["free_cost"] == 1655.8
    assert out["free_shares"] == pytest.approx(FREE_SHARES, abs=1e-12)
    # the fixed shares are the sequence's own guesses, whatever the free run's options say
    guesses = [ph.fraction for ph in contact_sequence(seven, _resolved(seven)).phases]
    assert out["fixed_shares"] == pytest.approx(guesses, abs=1e-12)
    assert math.fsum(out["fixed_shares"]) == pytest.approx(1.0, abs=1e-12)
    assert re.search(r"cost 30.1 % less on the coarse grid \(8\+5\+5\+5 knots\): released",
                     out["why"])


@pytest.mark.parametrize("change", ["failed", "not within", "no gain", "implausible",
                                    "no freeing stage", "freeing failed"])
def test_the_free_problem_first_is_not_kept_otherwise(seven: RobotModel, change: str) -> None:
    """Then the fixed-share problem is solved and ``decision`` chooses (None here)."""
    options = _resolved(seven).replace(free_phase_fractions=True)
    stages: tuple[StageRecord, ...] = COARSE
    if change == "no gain":
        stages = (COARSE[0], COARSE[1], _stage(FREEING_STAGE, 2313.0), COARSE[3])
    elif change == "no freeing stage":
        stages = (COARSE[0], COARSE[1], COARSE[3])
    elif change == "freeing failed":
        stages = (COARSE[0], COARSE[1], _stage(FREEING_STAGE, 1617.0, success=False))
    free = _fake_run(seven, options, FREE_SHARES, 1655.8, stages=stages,
                     success=change != "failed",
                     within=change != "not within")
    verdict = "verify fails swing.reversals (4 > 3 turns)" if change == "implausible" else None
    assert release_first(free, seven, lambda run: verdict) is None


def test_a_release_after_the_free_problem_first_lists_the_stages_as_they_ran(
        seven: RobotModel) -> None:
    options = _resolved(seven)
    own = _fake_run(seven, options, FREE_SHARES, 1655.8, stages=COARSE, wall=20.0)
    fixed_stage = dataclasses.replace(COARSE[3], name="check grid")
    fixed = _fake_run(seven, options, FIXED_SHARES, 2364.9, stages=(fixed_stage,), wall=30.0)
    warm_stage = dataclasses.replace(COARSE[3], name=PREFIX + "from the fixed shares: x")

    def solve_free(free_options: GaitOptions, start: Any) -> Any:
        return _fake_run(seven, free_options, FREE_SHARES, 1655.0, wall=25.0,
                         stages=own.stages + (warm_stage,))

    run = release_shares(fixed, solve_free, lambda run: None, first=own)
    assert [s.name for s in run.stages] == [s.name for s in COARSE] + [
        "check grid", warm_stage.name]
    assert run.share_release["released"] is True and "fixed_knots" not in run.share_release
    assert run.wall_time_s == pytest.approx(55.0)


def test_the_plausibility_check_runs_once_per_run() -> None:
    import gaitopt.gait.api as api

    calls: list[Any] = []
    judged = api._judged_once(lambda run: calls.append(run) or "why")
    a, b = SimpleNamespace(), SimpleNamespace()
    assert [judged(a), judged(a), judged(b), judged(a)] == ["why"] * 4
    assert calls == [a, b]


@pytest.mark.parametrize(("flag", "value"), [([], None), (["--fixed-fractions"], False),
                                              (["--free-fractions"], True)])
def test_the_command_line_passes_the_choice_and_the_verify_check(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Any, flag: list[str],
        value: bool | None) -> None:
    """``gaitopt solve``: no flag leaves the shares to the sequence (released where they are
    guesses), ``--fixed-fractions`` / ``--free-fractions`` decide; the solve gets
    a :class:`~gaitopt.analysis.plausible.Verifier` (``verified``, remembering each report)
    as its plausibility check."""
    from click.testing import CliRunner

    import gaitopt.gait.api as api
    from gaitopt.cli import cli

    seen: dict[str, Any] = {}

    def capture(model: Any, options: GaitOptions, **kwargs: Any) -> Any:
        seen.update(options=options, **kwargs)
        raise SystemExit(0)

    monkeypatch.setattr(api, "solve_staged_run", capture)
    result = CliRunner().invoke(cli, ["solve", "--model", "seven-link", "--speed", "30m/min",
                                      *flag, "-o", str(tmp_path / "g.gait.json")])
    assert result.exit_code == 0, result.output
    assert seen["options"].free_phase_fractions is value
    assert isinstance(seen["plausible"], Verifier)


# -- the seven-link default solves (slow: minutes each) -------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize(("speed", "released"), [(0.5, True), (4 / 3, True), (0.2, None)])
def test_the_seven_link_default_releases_its_shares_where_plausible(
        seven: RobotModel, speed: float, released: bool | None) -> None:
    """30 m/min: the released optimum costs about 40 % less and passes verify; 80 m/min:
    about 22 % less (1804.4 against 2319.3), reached by the free problem's own stages after
    the start from the fixed-share optimum crawled (its check grid at the limit); 12 m/min:
    the fixed shares are kept (the free optimum flaps the foot, swing.reversals fails; with
    the release's iteration limit its target grid stops there first), or, since the held
    check grid keeps the free optimum on 36 + 26 knots, released (3608.9, 2 ankle turns there;
    4 on the finer grids it was refined to before): the slow walk's free optimum lies at the
    edge of the flapping check, so either (None). Whichever, the answer is converged to 1 %
    and verified (docs/feet.md, "Free phase shares by default")."""
    run = solve_staged_run(seven, GaitOptions(speed=speed), plausible=verified)
    assert run.success and run.share_release is not None
    record = run.share_release
    if released is None:
        released = bool(record["released"])
    assert record["released"] is released
    assert (run.accuracy_extra or {}).get("within_target") is True
    gait = gait_from_run(run)
    assert verify_gait(gait).passed
    assert gait.solver["phase_shares"] == record
    assert any(s.name.startswith(PREFIX) for s in run.stages)
    if released and "fixed_knots" in record:  # kept first: compared on the coarse grid
        assert record["coarse_free_cost"] < (1.0 - SAME_COST) * record["fixed_cost"]
        assert not any(s.name.startswith("target grid") for s in run.stages)
    elif released:
        assert record["free_cost"] < 0.8 * record["fixed_cost"]
    if released:
        assert gait.cost_value == pytest.approx(record["free_cost"], rel=1e-9)
        assert gait.options["free_phase_fractions"] is True
    else:
        assert "fixed shares kept" in record["why"]
        assert ("swing.reversals" in record["why"] or "free-share solve failed" in record["why"]
                or "not converged" in record["why"])
        assert gait.cost_value == pytest.approx(record["fixed_cost"], rel=1e-9)
        assert [round(s, 6) for s in shares_of(run)] == pytest.approx(FIXED_SHARES, abs=1e-6)


def test_a_stage_time_limit_fails_the_stage_that_reaches_it() -> None:
    """``solve_walking(stage_seconds=...)`` (the released solve's bound) passes IPOPT's wall-time
    limit to every stage: a limit no stage can meet fails the first one, reported as failed,
    while the same solve without it converges."""
    from gaitopt.gait.solve.staged import solve_walking

    model = load_model("five-link")
    options = GaitOptions(knots=(8, 5), knot_spacing="uniform", accuracy=None)
    bounded = solve_walking(model, options, stage_seconds=1e-9)
    assert not bounded.success
    assert bounded.stages[0].status == "Maximum_WallTime_Exceeded"
    assert solve_walking(model, options).success


@pytest.mark.parametrize(("given", "in_file", "solved"), [
    (None, True, True), (None, None, None), (False, True, False), (None, False, None)])
def test_a_warm_start_from_a_file_with_free_shares_keeps_them_free(
        monkeypatch: pytest.MonkeyPatch, seven: RobotModel, given: bool | None,
        in_file: bool | None, solved: bool | None) -> None:
    """A released file (its ``free_phase_fractions`` true) starts a problem with the shares
    free unless the caller fixes them: from the fixed-share problem the warm start left the
    file's optimum (2325 against 1663 at 63 m/min, measured from the released 60 m/min
    walk)."""
    import gaitopt.gait.api as api

    seen: list[GaitOptions] = []

    def capture(model: Any, options: GaitOptions, **kwargs: Any) -> Any:
        seen.append(options)
        raise SystemExit(0)

    monkeypatch.setattr(api, "solve_walking", capture)
    monkeypatch.setattr(api, "warm_start_usable", lambda *a: False)
    monkeypatch.setattr(api, "refuse_unwalkable", lambda *a, **k: None)
    gait = SimpleNamespace(options={"free_phase_fractions": in_file})
    with pytest.raises(SystemExit):
        solve_staged_run(seven, GaitOptions(speed=1.05, free_phase_fractions=given),
                         warm_start=gait)  # type: ignore[arg-type]
    assert seen[0].free_phase_fractions is solved
