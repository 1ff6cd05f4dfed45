"""Feet: the seven-link model walks heel-toe through the same contact-sequence mechanism.

Checked independently of gaitopt's dynamics with Pinocchio at every knot (equations of motion
with the saved forces), the held points where the sequence puts them (heel at 0, toe one foot
length ahead, the other heel one step ahead) at rest, and by ``verify``."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.api import solve_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.contact_sequence import sequence_from_dict
from gaitopt.robot.model import RobotModel
from tests.gait.conftest import EOM_RTOL, Reference, eom_residuals

RefFn = Callable[[RobotModel], Reference]


@pytest.mark.slow
def test_seven_link_heel_toe_walk_is_physical(reference: RefFn, tmp_path) -> None:  # noqa: ANN001
    # 30 m/min on 24+16 knots (the grid docs/feet.md recommends; coarser ones fail verify
    # between knots, and a slow step of 3.5 s at 12 m/min needs a finer one still).
    options = GaitOptions(formulation="full", gait="heel-toe", speed=0.5, knots=(24, 16),
                          min_stance_knee_flexion=0.0)
    gait = Gait.load(solve_gait("seven-link", options).save(tmp_path / "feet.gait.json"))
    assert gait.success and gait.contact_sequence is not None
    assert [ph.name for ph in gait.phases] == ["foot_flat", "heel_off", "double_support",
                                               "heel_rocker"]
    assert 0.6 < gait.step_length < 0.8   # a human-like step (docs/feet.md: 0.743 m)
    ref = reference(gait.model)
    seq = sequence_from_dict(dict(gait.contact_sequence))
    nq = gait.model.nq
    for i, ph in enumerate(gait.phases):
        res = eom_residuals(ref, ph)
        assert np.all(res < EOM_RTOL), (ph.name, res)
        for spec in seq.phases[i].held:
            name, _, axes = spec.partition(":")
            for k in range(1, ph.t.size):
                p, v, _ = ref.tip_kinematics(ph.q[k], ph.qd[k], np.zeros(nq), name)
                assert abs(p[1]) < 1e-6 and abs(v[1]) < 1e-6, (ph.name, name, k, p, v)
                if not axes:
                    assert abs(p[0] - seq.ground_x(name, gait.step_length)) < 1e-6
                    assert abs(v[0]) < 1e-6
            assert np.all(ph.contact_forces[name][:, 1] > -1e-6)   # pushes, never pulls
    report = verify_gait(gait)
    assert report.passed, report.failed_ids
