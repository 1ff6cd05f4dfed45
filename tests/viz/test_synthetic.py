"""The synthetic gait used by the figure tests is itself plausible and periodic."""

from __future__ import annotations

import numpy as np

from gaitopt.robot.symmetry import swap_permutations
from tests.viz.synthetic import forward_kinematics, synthetic_gait


def test_stance_tips_stay_on_the_ground_and_swing_tip_above() -> None:
    gait = synthetic_gait(speed=0.4, step_length=0.3)
    single, double = gait.phases
    fk1, fk2 = forward_kinematics(gait.model, single.q), forward_kinematics(gait.model, double.q)
    np.testing.assert_allclose(fk1["tip_1"], 0.0, atol=1e-12)
    np.testing.assert_allclose(fk2["tip_1"], 0.0, atol=1e-12)
    np.testing.assert_allclose(fk2["tip_2"], np.tile([0.3, 0.0], (double.t.size, 1)), atol=1e-12)
    assert np.all(fk1["tip_2"][1:-1, 1] > 0.0)
    assert np.all(single.q[:, [4, 6]] <= 0.0)  # knees never hyperextend


def test_state_is_periodic_with_legs_swapped_and_shifted() -> None:
    gait = synthetic_gait(speed=0.5, step_length=0.4)
    perm_q, _ = swap_permutations(gait.model)
    q_end = gait.phases[-1].q[-1][perm_q]
    q_end[0] -= gait.step_length
    np.testing.assert_allclose(q_end, gait.phases[0].q[0], atol=1e-12)


def test_velocities_are_derivatives_of_positions() -> None:
    gait = synthetic_gait()
    s = gait.samples
    first = s.t < gait.parameters["single_support_time"]
    t, q, qd = s.t[first], s.q[first], s.qd[first]
    np.testing.assert_allclose(np.gradient(q, t, axis=0)[1:-1], qd[1:-1], atol=2e-2)
