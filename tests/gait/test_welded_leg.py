"""A leg welded into the base: the kneed compass gait of ``tests/gait/data/kcg.yaml`` (thigh 1
is the floating base), whose leg swap is no permutation of the coordinates (the base angle
becomes the other thigh's, :func:`gaitopt.robot.symmetry.swap_matrices`). Its periodic walk
in full coordinates (the paper's walk: point feet, single then double support) solves, is
physical by Pinocchio's equations, periodic through the linear swap, and passes verify."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.robot.model import RobotModel
from tests.gait.conftest import (
    Reference,
    SolveFn,
    assert_physics,
    periodicity_errors,
    recomputed_cost,
)

RefFn = Callable[[RobotModel], Reference]
KCG = Path(__file__).parent / "data" / "kcg.yaml"


def test_the_walk_of_a_kneed_compass_gait_with_a_welded_thigh(solved: SolveFn,
                                                              reference: RefFn) -> None:
    """12 m/min, 16+6 knots, from the naive start: converged; the equations of motion hold
    (Pinocchio), the step is periodic through ``S_q`` (its base angle after the step is the
    other thigh's, ``base + hip``), the cost is the controls', verify passes."""
    gait = solved(GaitOptions(formulation="full", knots=(16, 6)), str(KCG)).gait
    assert gait.success
    assert_physics(reference(gait.model), gait)
    state, _ = periodicity_errors(gait, controls=())
    assert state < 1e-6
    assert recomputed_cost(gait) == pytest.approx(gait.cost_value, rel=1e-6)
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


def test_periodic_controls_flip_the_sign_of_the_welded_hip(solved: SolveFn) -> None:
    """With the paper's control model (controls continuous and periodic) the controls at
    the start of the step are ``S_u`` of those at its end: the knee torques exchanged and the
    hip torque (thigh 2 against thigh 1, which exchange roles) with its sign flipped."""
    gait = solved(GaitOptions(formulation="full", control_model="paper"), str(KCG)).gait
    assert gait.success
    state, control = periodicity_errors(gait, controls=("hip", "knee_1", "knee_2"))
    assert state < 1e-6 and control < 1e-6
    hip_start, hip_end = gait.phases[0].u[0][0], gait.phases[-1].u[-1][0]
    assert abs(hip_start) > 1e-2 and hip_start == pytest.approx(-hip_end, abs=1e-6)
