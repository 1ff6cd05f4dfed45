"""People's joint angles over a stride (gaitopt.analysis.joint_angles): the signs of the
angles, stance as the foot's contact phases, excursions as max - min over the stride, the
measures on a synthetic stride, and the figure. The gait-file tests compare with quantities
computed another way from the same file (event times, the file's own samples), never with
a solver's digits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gaitopt import Gait
from gaitopt.analysis.joint_angles import (
    MEASURES,
    PEOPLE,
    JointAngleStride,
    distance_from_people,
    joint_angle_stride,
    leg_joints,
    people_measures,
    relative_errors,
    stance_intervals,
)

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def gait() -> Gait:
    return Gait.load(DATA / "seven_link_60.gait.json")


def event_time(gait: Gait, name: str) -> float:
    return next(e.t for e in gait.events if e.name == name)


def synthetic(percent: np.ndarray, knee: np.ndarray, stance_end: float = 60.0
              ) -> JointAngleStride:
    hip = 10.0 + 20.0 * np.sin(2 * np.pi * percent / 100.0)  # excursion 40
    ankle = -5.0 + 15.0 * np.cos(2 * np.pi * percent / 100.0)  # excursion 30
    return JointAngleStride(leg=("heel_1", "toe_1"), joints=("hip_1", "knee_1", "ankle_1"),
                            percent=percent, hip=hip, knee=knee, ankle=ankle,
                            stance=percent <= stance_end, stance_end=stance_end,
                            stride_time=1.0)


def test_a_stride_with_people_s_values_has_distance_zero() -> None:
    p = np.linspace(0.0, 100.0, 2001)
    bump = lambda c, w, h: h * np.exp(-(((p - c) / w) ** 2))  # noqa: E731
    # Stance to 60 %: a loading-response bump of 17.5 deg at 15 %, the knee bending to 40 deg
    # before toe-off (second half of stance: not the stance peak), 60 deg in swing.
    knee = bump(15.0, 5.0, 17.5) + bump(62.0, 6.0, 40.0) + bump(72.0, 8.0, 60.0)
    a = synthetic(p, knee)
    m = people_measures(a)
    assert m["stance_knee_flexion"] == pytest.approx(17.5, abs=1e-3)
    assert m["stance_knee_flexion_percent"] == pytest.approx(15.0, abs=0.1)
    assert m["swing_knee_flexion"] == pytest.approx(np.max(knee[p > 60.0]))
    assert m["hip_excursion"] == pytest.approx(40.0, abs=1e-3)
    assert m["ankle_excursion"] == pytest.approx(30.0, abs=1e-3)
    errors = relative_errors({**m, "swing_knee_flexion": 60.0})
    assert set(errors) == set(MEASURES)
    assert distance_from_people({**m, "swing_knee_flexion": 60.0}) == pytest.approx(0.0,
                                                                                    abs=1e-4)


def test_the_distance_is_the_sum_of_relative_errors_against_the_middle_of_a_range() -> None:
    m = {"stance_knee_flexion": 35.0, "swing_knee_flexion": 30.0, "hip_excursion": 40.0,
         "ankle_excursion": 45.0}
    assert sum(PEOPLE["stance_knee_flexion"]) / 2 == 17.5
    assert relative_errors(m) == pytest.approx({"stance_knee_flexion": 1.0,
                                                "swing_knee_flexion": 0.5,
                                                "hip_excursion": 0.0,
                                                "ankle_excursion": 0.5})
    assert distance_from_people(m) == pytest.approx(2.0)


def test_the_stance_peak_is_taken_over_the_first_half_of_stance_only() -> None:
    p = np.linspace(0.0, 100.0, 1001)
    knee = np.where(p < 45.0, 5.0, 50.0)  # flexed only late in stance (stance ends at 60)
    m = people_measures(synthetic(p, knee))
    assert m["stance_knee_flexion"] == 5.0
    assert m["swing_knee_flexion"] == 50.0


def test_the_seven_link_leg_is_hip_knee_ankle(gait: Gait) -> None:
    assert leg_joints(gait.model, ("heel_1", "toe_1")) == ("hip_1", "knee_1", "ankle_1")
    assert leg_joints(gait.model, ("heel_2", "toe_2")) == ("hip_2", "knee_2", "ankle_2")


def test_stance_runs_from_the_heel_strike_to_the_toe_off_of_the_next_step(gait: Gait) -> None:
    # Leg 1 holds heel_1/toe_1 from the step's start to toe_off; in the swapped second step
    # it is the file's leg 2, which strikes at heel_strike: one stance across the stride's
    # end, from T + t(heel_strike) to 2 T + t(toe_off).
    step = gait.step_time
    (start, end), = stance_intervals(gait, ("heel_1", "toe_1"))
    assert start == pytest.approx(step + event_time(gait, "heel_strike"), abs=1e-12)
    assert end == pytest.approx(2 * step + event_time(gait, "toe_off"), abs=1e-12)
    a = joint_angle_stride(gait)
    # The heel-toe walk's shares are fixed: stance is (1 + double support share) / 2 of the
    # stride, 57.5 % with 0.15.
    assert a.stance_end == pytest.approx(100 * (end - start) / (2 * step), abs=1e-9)
    assert a.stance_end == pytest.approx(57.5, abs=1e-6)
    assert a.percent[0] == 0.0 and a.percent[-1] == 100.0
    assert np.all(np.diff(a.percent) >= 0)
    assert a.stance[a.percent < a.stance_end - 1e-6].all()
    assert not a.stance[(a.percent > a.stance_end + 1e-6) & (a.percent < 100.0)].any()


def test_signs_and_excursions_follow_the_file_s_coordinates(gait: Gait) -> None:
    model, s = gait.model, gait.samples
    a = joint_angle_stride(gait)

    def deg(joint: str) -> np.ndarray:
        return np.degrees(s.q[:, model.joint_coordinate(joint)])

    # Leg 1 over the stride: the file's leg 1 in the first step, its leg 2 in the second.
    hip = np.concatenate([deg("hip_1"), deg("hip_2")])
    knee = np.concatenate([deg("knee_1"), deg("knee_2")])
    ankle = np.concatenate([deg("ankle_1"), deg("ankle_2")])
    assert a.hip.max() == pytest.approx(hip.max()) and a.hip.min() == pytest.approx(hip.min())
    assert a.knee.max() == pytest.approx(-knee.min())  # flexion positive: the model's -q
    assert a.ankle.min() == pytest.approx(ankle.min())
    assert np.all(a.knee > -1.0)  # a knee bends one way only (the limit is 0; samples may
    # overshoot it a little between knots)
    m = people_measures(a)
    assert m["hip_excursion"] == pytest.approx(np.ptp(hip))
    assert m["ankle_excursion"] == pytest.approx(np.ptp(ankle))
    # At the heel strike (0 and 100 %) the angles are the file's leg 2's at the heel strike
    # event, interpolated between the samples either side of it.
    t = event_time(gait, "heel_strike")
    for ours, theirs in ((a.hip, deg("hip_2")), (a.knee, -deg("knee_2")),
                         (a.ankle, deg("ankle_2"))):
        assert ours[0] == pytest.approx(np.interp(t, s.t, theirs), abs=1e-9)
        assert ours[-1] == ours[0]


def test_the_swing_peak_is_the_largest_flexion_outside_the_contact_phases(gait: Gait) -> None:
    s = gait.samples
    knee_1 = -np.degrees(s.q[:, gait.model.joint_coordinate("knee_1")])
    knee_2 = -np.degrees(s.q[:, gait.model.joint_coordinate("knee_2")])
    # Leg 1 swings after its toe_off in the first step, and before the file's leg 2 strikes
    # in the second (swapped) one.
    swing = np.concatenate([knee_1[s.t > event_time(gait, "toe_off")],
                            knee_2[s.t < event_time(gait, "heel_strike")]])
    m = people_measures(joint_angle_stride(gait))
    assert m["swing_knee_flexion"] == pytest.approx(swing.max())


def test_both_legs_of_a_symmetric_gait_measure_the_same(gait: Gait) -> None:
    one = people_measures(joint_angle_stride(gait, 0))
    two = people_measures(joint_angle_stride(gait, 1))
    assert one == pytest.approx(two, abs=1e-9)


def test_the_figure_has_three_angle_panels_and_the_measures(gait: Gait) -> None:
    from gaitopt.viz.joint_angles import joint_angles_figure

    fig = joint_angles_figure([("a", gait), ("b", gait)])
    axes = fig.get_axes()
    assert len(axes) == 4
    assert [ax.get_ylabel() for ax in axes[:3]] == ["hip flexion  [deg]", "knee flexion  [deg]",
                                                    "ankle dorsiflexion  [deg]"]
    assert any(legend.get_gid() == "gaits" for legend in fig.legends)
