"""The swing of each leg (gaitopt.analysis.checks.swing): turns of the distal joint, the
joining of a swing across the period's end, and the verify check built on them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gaitopt import Gait
from gaitopt.analysis.checks.check import LIMITS
from gaitopt.analysis.checks.swing import (
    REVERSAL_HYSTERESIS,
    count_reversals,
    swing_checks,
    swings,
)

DATA = Path(__file__).parent / "data"


@pytest.mark.parametrize(("half_waves", "expected"), [(1, 0), (2, 1), (3, 2), (10, 9)])
def test_a_sine_of_n_half_waves_turns_n_minus_one_times(half_waves: int, expected: int) -> None:
    t = np.linspace(0.0, 1.0, 2001)
    x = 0.3 * np.sin(np.pi * half_waves * t - np.pi / 2)  # starts at a trough: monotone pieces
    assert count_reversals(x, REVERSAL_HYSTERESIS) == expected


def test_ripples_below_the_hysteresis_do_not_count() -> None:
    t = np.linspace(0.0, 1.0, 2001)
    ripple = 0.4 * REVERSAL_HYSTERESIS * np.sin(2 * np.pi * 40 * t)
    assert count_reversals(0.2 * t + ripple, REVERSAL_HYSTERESIS) == 0
    # The same ripple at three times the hysteresis: each of the 40 periods' crest and
    # trough counts.
    assert count_reversals(7.5 * ripple, REVERSAL_HYSTERESIS) == 80


def test_a_turn_counts_once_the_angle_has_gone_back_past_the_hysteresis() -> None:
    h = REVERSAL_HYSTERESIS
    assert count_reversals(np.array([0.0, 1.0, 1.0 - 0.99 * h]), h) == 0
    assert count_reversals(np.array([0.0, 1.0, 1.0 - 1.01 * h]), h) == 1
    assert count_reversals(np.array([0.0]), h) == 0


def test_the_point_foot_swing_is_the_swing_tips_single_support() -> None:
    gait = Gait.load(DATA / "five_link_12.gait.json")
    (sw,) = swings(gait)
    assert sw.leg == ("tip_2",) and sw.joint == "knee_2"
    single = gait.phases[0]
    assert sw.t[0] == pytest.approx(single.t[0]) and sw.t[-1] == pytest.approx(single.t[-1])
    assert sw.reversals <= 2  # the knee bends once and straightens
    assert 0.0 < sw.peak_height < 0.05


def test_a_heel_toe_swing_is_joined_across_the_step_through_the_leg_swap() -> None:
    gait = Gait.load(DATA / "seven_link_60.gait.json")
    (sw,) = swings(gait)
    # Leg 1 leaves the ground at toe-off (double support's end) and lands as leg 2 at the next
    # step's heel strike: one swing, from toe-off to the heel strike a step time later.
    toe_off = gait.phases[2].t[-1]
    heel_strike = gait.phases[1].t[-1]
    assert sw.leg == ("heel_1", "toe_1") and sw.joint == "ankle_1"
    assert sw.t[0] == pytest.approx(toe_off)
    assert sw.t[-1] == pytest.approx(heel_strike + gait.step_time)
    assert np.all(np.diff(sw.t) >= 0.0)
    # The joined angle is continuous where the runs meet (the swap maps ankle_1 to ankle_2).
    gaps = np.abs(np.diff(sw.angle))
    assert gaps.max() < 0.1


def test_the_check_counts_the_worst_swing_and_fails_a_flapping_foot() -> None:
    gait = Gait.load(DATA / "heel_toe_60.gait.json")
    (check,) = swing_checks(gait, dict(LIMITS))
    assert check.id == "swing.reversals"
    assert check.value == max(sw.reversals for sw in swings(gait))
    assert "ankle_1" in check.where
    flapping = swing_checks(gait, {**LIMITS, "swing.reversals": check.value - 1})
    assert not flapping[0].passed
