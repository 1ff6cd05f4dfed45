"""An answer the plausibility check rejects is solved again with a torque-rate term
(:mod:`gaitopt.gait.solve.torque_rate_fallback`): kept where it passes, recorded either way.

The five-link walk at 12 m/min stands in for a rejected answer (a check that rejects what it
is told to), so that the mechanism is tested in seconds; the seven-link run at 400 m/min, whose
swing ankle really fails ``swing.reversals``, is the slow test at the end."""

from __future__ import annotations

import pytest

from gaitopt.analysis.plausible import verified
from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.api import solve_gait, solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve.staged_run import StagedRun
from gaitopt.gait.solve.torque_rate_fallback import (
    FALLBACK_TORQUE_RATE_TIMES,
    PREFIX,
    fallback_line,
)

WALK = GaitOptions(speed=0.2, knots=(16, 6))


def _without_term(run: StagedRun) -> str | None:
    """Rejects every answer whose cost has no torque-rate term."""
    return None if run.options.torque_rate_time > 0.0 else "rejected for the test"


def test_a_rejected_answer_is_replaced_by_the_optimum_with_the_torque_rate_term() -> None:
    """The kept answer is the optimum of the problem with the first ``torque_rate_time``
    (0.02 s) solved directly (the same cost to the solver's accuracy), the first answer's
    cost is the plain optimum's, and the file says what was done."""
    tau = FALLBACK_TORQUE_RATE_TIMES[0]
    plain = solve_gait("five-link", WALK)
    direct = solve_gait("five-link", WALK.replace(torque_rate_time=tau))
    gait = solve_gait("five-link", WALK, plausible=_without_term)
    assert gait.success
    assert gait.options["torque_rate_time"] == tau
    assert "0.02 s" in gait.cost["formula"]
    record = gait.solver["torque_rate_fallback"]
    assert record["kept"] is True and record["torque_rate_time"] == tau
    assert record["why"] == "rejected for the test"
    assert record["first_cost"] == pytest.approx(plain.cost_value, rel=1e-6)
    assert gait.cost_value == pytest.approx(direct.cost_value, rel=1e-5)
    assert record["tries"] == [{"torque_rate_time": tau, "cost": gait.cost_value,
                                "verdict": None}]
    assert gait.cost_value > plain.cost_value  # the term adds a positive integral
    names = [s["name"] for s in gait.solver["stages"]]
    assert any(n.startswith(PREFIX) for n in names)
    assert names.index(next(n for n in names if n.startswith(PREFIX))) > 0
    assert gait.solver["accuracy"]["cost_error"] is not None  # its own check grid
    assert "this answer (tau 0.02 s" in fallback_line(record)


def test_a_smoothed_answer_that_is_rejected_too_leaves_the_first_standing() -> None:
    """Where the check rejects every smoothed answer too (each ``tau`` in turn, a larger
    one costing more), the first answer is the gait (its cost without the term) and the
    record says why none was kept."""
    plain = solve_gait("five-link", WALK)
    gait = solve_gait("five-link", WALK, plausible=lambda run: "always rejected")
    assert gait.success
    assert gait.options["torque_rate_time"] == 0.0
    assert gait.cost_value == pytest.approx(plain.cost_value, rel=1e-6)
    record = gait.solver["torque_rate_fallback"]
    assert record["kept"] is False and record["torque_rate_time"] is None
    tries = record["tries"]
    assert [t["torque_rate_time"] for t in tries] == list(FALLBACK_TORQUE_RATE_TIMES)
    assert all(t["verdict"] == "always rejected" for t in tries)
    costs = [record["first_cost"]] + [t["cost"] for t in tries]
    assert costs == sorted(costs) and len(set(costs)) == len(costs)
    assert "the first answer stands" in fallback_line(record)


def test_a_plausible_answer_or_a_cost_with_the_term_is_not_solved_again() -> None:
    """A plausible answer is judged once and kept; a cost that has a torque-rate term
    already is not smoothed again, whatever the check says; nor is any answer where the
    caller turns the fallback off."""
    calls: list[float] = []

    def plausible(run: StagedRun) -> str | None:
        calls.append(run.options.torque_rate_time)
        return None

    gait = solve_gait("five-link", WALK, plausible=plausible)
    assert calls == [0.0]
    assert "torque_rate_fallback" not in gait.solver
    assert not any(s["name"].startswith(PREFIX) for s in gait.solver["stages"])
    rated = solve_gait("five-link", WALK.replace(torque_rate_time=0.01),
                       plausible=lambda run: "always rejected")
    assert "torque_rate_fallback" not in rated.solver
    assert rated.options["torque_rate_time"] == 0.01
    unsmoothed = solve_staged_run("five-link", WALK, plausible=lambda run: "always rejected",
                                  smooth_rejected=False)  # gaitopt solve --no-verify
    assert unsmoothed.torque_rate_fallback is None
    assert unsmoothed.options.torque_rate_time == 0.0


def test_an_answer_outside_its_accuracy_target_is_not_smoothed() -> None:
    """An answer refined toward an accuracy it did not reach is reported as such (exit
    status 3 from ``gaitopt solve``), not smoothed: the check rejects it for its accuracy,
    which the term does not mend (smoothing it once refined past 400 knots a phase)."""
    run = solve_staged_run("five-link", GaitOptions(speed=0.5, ankle=False, impulse=False,
                                                    accuracy=1e-5),
                           plausible=lambda run: "always rejected")
    assert run.success
    assert run.accuracy_extra is not None and run.accuracy_extra["within_target"] is False
    assert run.torque_rate_fallback is None
    assert not any(s.name.startswith(PREFIX) for s in run.stages)


@pytest.mark.slow
def test_the_seven_link_run_at_400_m_per_min_passes_verify_from_the_default_solve() -> None:
    """Its optimum without the term holds the swing ankle on its plantarflexion limit and
    fails ``swing.reversals`` (6 turns, J 7550.9); solved again with the term it passes
    (J 7745.0, +2.6 %, docs/running.md), as ``gaitopt solve`` gives it."""
    gait = solve_gait("seven-link", GaitOptions(gait="run", impulse=False, speed=400.0 / 60.0),
                      plausible=verified)
    assert gait.success
    record = gait.solver["torque_rate_fallback"]
    assert "swing.reversals" in record["why"]
    assert record["kept"] is True and record["torque_rate_time"] == 0.02
    assert 1.0 < gait.cost_value / record["first_cost"] < 1.05  # measured 1.026
    assert gait.solver["accuracy"]["within_target"]
    report = verify_gait(gait)
    assert report.passed, report.failed_ids
