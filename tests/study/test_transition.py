"""The walk-run transition on synthetic cost curves (:mod:`gaitopt.study.transition`): the
bracket, the interpolated crossing, the grid-error interval, no crossing, crossings at the
grid's ends and failed points. Pure functions: exact or 1e-12 comparisons."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gaitopt.study.transition import crossing, froude_number, walk_run_transition

NAN = math.nan


def lines(speeds: list[float], walk: tuple[float, float], run: tuple[float, float]
          ) -> tuple[list[float], list[float]]:
    """Two straight cost curves ``a + b v`` at ``speeds``."""
    return ([walk[0] + walk[1] * v for v in speeds], [run[0] + run[1] * v for v in speeds])


def test_straight_lines_cross_where_they_meet() -> None:
    # walk 1 + 2 v, run 4 + 0.5 v: equal at v = 2 (exactly representable)
    speeds = [0.5, 1.0, 1.5, 2.5, 3.0]
    walk, run = lines(speeds, (1.0, 2.0), (4.0, 0.5))
    t = walk_run_transition(speeds, walk, run)
    assert t.kind == "crossing"
    assert t.bracket == (1.5, 2.5)
    assert t.speed == pytest.approx(2.0, rel=1e-12)
    assert t.changes == 1 and t.skipped == ()
    # no error estimate given: the interval is the crossing itself, the four unknowns counted
    assert t.interval == (t.speed, t.speed) and t.uncertainty == 0.0
    assert t.unknown_errors == 4


def test_crossing_of_curved_costs_is_linear_between_grid_speeds() -> None:
    speeds = [1.0, 2.0]
    walk, run = [1.0, 9.0], [3.0, 5.0]  # D = 2, -4: the lines cross a third of the way
    t = walk_run_transition(speeds, walk, run)
    assert t.speed == pytest.approx(1.0 + 1.0 / 3.0, rel=1e-12)


def test_grid_error_interval_moves_both_ends_of_the_difference() -> None:
    speeds = [1.0, 2.0]
    walk, run = [1.0, 3.0], [2.0, 2.0]  # D = 1, -1: crossing at 1.5
    t = walk_run_transition(speeds, walk, run, walk_error=[0.1, -0.1], run_error=[0.1, 0.2])
    # D moved by -(0.2, 0.3): 0.8, -1.3 -> 1 + 0.8 / 2.1; by +(0.2, 0.3): 1.2, -0.7 -> 1 + 1.2/1.9
    assert t.speed == pytest.approx(1.5, rel=1e-12)
    assert t.interval[0] == pytest.approx(1.0 + 0.8 / 2.1, rel=1e-12)
    assert t.interval[1] == pytest.approx(1.0 + 1.2 / 1.9, rel=1e-12)
    assert t.interval[0] < t.speed < t.interval[1]
    assert t.uncertainty == pytest.approx(0.5 * (t.interval[1] - t.interval[0]), rel=1e-12)
    assert not t.leaves_bracket and t.unknown_errors == 0


def test_a_grid_error_larger_than_the_difference_reaches_the_bracket() -> None:
    speeds = [1.0, 2.0, 3.0]
    walk, run = [1.0, 2.0, 3.0], [1.5, 1.9, 2.0]  # D = 0.5, -0.1, -1: bracket 1-2
    t = walk_run_transition(speeds, walk, run, walk_error=[0.0, 0.3, 0.0],
                            run_error=[0.0, 0.0, 0.0])
    assert t.bracket == (1.0, 2.0)
    assert t.interval[1] == 2.0 and t.leaves_bracket
    assert t.interval[0] == pytest.approx(1.0 + 0.5 / 0.9, rel=1e-12)


def test_unknown_errors_count_as_zero_and_are_counted() -> None:
    speeds = [1.0, 2.0]
    t = walk_run_transition(speeds, [1.0, 3.0], [2.0, 2.0], walk_error=[0.1, NAN],
                            run_error=[NAN, NAN])
    assert t.unknown_errors == 3
    assert t.interval[0] == pytest.approx(1.0 + 0.9 / 1.9, rel=1e-12)


@pytest.mark.parametrize(("walk", "run", "kind", "changes"), [
    ([1.0, 2.0, 3.0], [2.0, 3.0, 4.0], "walk", 0),        # the walk cheaper everywhere
    ([2.0, 3.0, 4.0], [1.0, 2.0, 3.0], "run", 0),         # the run cheaper everywhere
    ([2.0, 2.0, 2.0], [2.0, 2.0, 2.0], "run", 0),         # equal: not cheaper
    ([2.0, 1.0, 1.0], [1.0, 2.0, 3.0], "run-to-walk", 1),  # the opposite order
])
def test_no_walk_to_run_crossing(walk: list[float], run: list[float], kind: str,
                                 changes: int) -> None:
    t = walk_run_transition([1.0, 2.0, 3.0], walk, run)
    assert t.kind == kind and t.changes == changes
    assert math.isnan(t.speed) and all(math.isnan(b) for b in t.bracket + t.interval)


def test_crossing_in_the_first_and_the_last_interval() -> None:
    speeds = [1.0, 2.0, 3.0, 4.0]
    first = walk_run_transition(speeds, [1.0, 3.0, 4.0, 5.0], [2.0, 2.0, 3.0, 4.0])
    assert first.bracket == (1.0, 2.0) and first.speed == pytest.approx(1.5, rel=1e-12)
    last = walk_run_transition(speeds, [1.0, 2.0, 3.0, 5.0], [2.0, 3.0, 4.0, 4.0])
    assert last.bracket == (3.0, 4.0) and last.speed == pytest.approx(3.5, rel=1e-12)


def test_equal_costs_at_a_grid_speed_put_the_crossing_on_it() -> None:
    t = walk_run_transition([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [2.0, 2.0, 2.0])
    assert t.bracket == (1.0, 2.0) and t.speed == 2.0


def test_failed_points_are_skipped_and_widen_the_bracket() -> None:
    speeds = [1.0, 2.0, 3.0, 4.0, 5.0]
    walk = [1.0, 2.0, NAN, 4.0, 5.0]   # the walk failed at 3
    run = [2.0, 3.0, 3.0, NAN, 3.0]    # the run failed at 4
    t = walk_run_transition(speeds, walk, run)
    assert t.speeds == (1.0, 2.0, 5.0) and t.skipped == (3.0, 4.0)
    assert t.bracket == (2.0, 5.0)
    assert t.speed == pytest.approx(2.0 + 3.0 * 1.0 / 3.0, rel=1e-12)  # D = 1, -2


def test_too_few_common_speeds_cannot_tell() -> None:
    t = walk_run_transition([1.0, 2.0, 3.0], [1.0, NAN, NAN], [NAN, 2.0, 3.0])
    assert t.kind == "none" and t.speeds == () and t.skipped == (1.0, 2.0, 3.0)


def test_several_changes_report_the_last_walk_to_run_one() -> None:
    speeds = [1.0, 2.0, 3.0, 4.0, 5.0]
    d = np.array([1.0, -1.0, 1.0, -1.0, -2.0])  # walk, run, walk, run, run
    walk = [10.0] * 5
    t = walk_run_transition(speeds, walk, list(10.0 + d))
    assert t.bracket == (3.0, 4.0) and t.changes == 3
    # a run cheaper at the top speed only after walks: still the last walk-to-run change
    t = walk_run_transition(speeds, walk, list(10.0 + np.array([1.0, -1.0, 1.0, 1.0, -1.0])))
    assert t.bracket == (4.0, 5.0) and t.changes == 3


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError, match="one per speed"):
        walk_run_transition([1.0, 2.0], [1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="strictly ascending"):
        walk_run_transition([2.0, 1.0], [1.0, 2.0], [1.0, 2.0])


def test_crossing_and_froude_number() -> None:
    assert crossing(1.0, 3.0, 1.0, 1.0) == 2.0
    assert crossing(1.0, 3.0, 1.0, -1.0) == 2.0
    assert crossing(1.0, 3.0, 1.0, 2.0) == 1.0  # the zero at -1 lies outside: clipped
    # people's transition: 2 m/s on 0.9 m legs is a Froude number of about 0.45
    assert froude_number(2.0, 0.9) == pytest.approx(4.0 / (9.81 * 0.9), rel=1e-12)
    assert froude_number(math.sqrt(0.5 * 9.81), 1.0) == pytest.approx(0.5, rel=1e-12)
