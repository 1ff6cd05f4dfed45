"""The swing clearance profile (``GaitOptions.swing_clearance``): it holds at every knot and
collocation midpoint, and (to a small tolerance) between them, with the swing tip's height
from Pinocchio's kinematics, not the solver's."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from numpy.typing import NDArray

from gaitopt.gait.formulations.reduced import physics as walking
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.robot.biped import biped_of
from tests.gait.conftest import Reference, Solved, SolveFn

C = 0.02
#: The jumps control model on a modest grid: the clearance cost is converged there.
OPTIONS = GaitOptions(control_model="jumps", swing_clearance=C, knots=(16, 6))
#: Tolerances (m): at knots and midpoints the solver's constraint tolerance; between them
#: the interpolated motion may dip a little below the profile.
AT_POINTS = 1e-7
BETWEEN = 1e-3


def profile(s: NDArray[np.float64]) -> NDArray[np.float64]:
    """``c (4 s (1 - s))^2`` (the default, quartic profile)."""
    return C * (4.0 * s * (1.0 - s)) ** 2


@pytest.fixture(scope="module")
def cleared(solved: SolveFn) -> Solved:
    return solved(OPTIONS)


def swing_heights(ref: Reference, qs: NDArray[np.float64]) -> NDArray[np.float64]:
    swing = biped_of(ref.model).legs[1].contact
    zero = np.zeros(ref.model.nq)
    return np.array([ref.tip_kinematics(q, zero, zero, swing)[0][1] for q in qs])


def test_clearance_holds_at_knots_and_midpoints(
        cleared: Solved, reference: Callable[..., Reference]) -> None:
    assert cleared.solution.success
    gait, res = cleared.gait, cleared.solution.result
    ref = reference(gait.model)
    t1 = gait.parameters["single_support_time"]
    ss = res.phase(walking.SINGLE)
    mids = 0.5 * (ss.t[:-1] + ss.t[1:])
    q_mid = np.array([np.asarray(walking.single_support_to_full(gait.model, x)[0],
                                 dtype=float).ravel() for x in ss.x_at(mids)])
    for t, q in ((gait.phases[0].t, gait.phases[0].q), (mids, q_mid)):
        margin = swing_heights(ref, q) - profile(t / t1)
        assert margin.min() >= -AT_POINTS
    # The constraint is active somewhere (else it tested nothing): the tip touches it.
    knots = swing_heights(ref, gait.phases[0].q) - profile(gait.phases[0].t / t1)
    assert knots[1:-1].min() < 1e-4


def test_clearance_holds_on_the_dense_samples(
        cleared: Solved, reference: Callable[..., Reference]) -> None:
    gait = cleared.gait
    t1 = gait.parameters["single_support_time"]
    s = gait.samples
    single = s.t <= t1
    margin = swing_heights(reference(gait.model), s.q[single]) - profile(s.t[single] / t1)
    assert margin.min() >= -BETWEEN
    assert gait.samples.points["tip_2"][single, 1].max() >= C - BETWEEN


def test_clearance_costs_energy(cleared: Solved, solved: SolveFn) -> None:
    """A constraint that is active raises the optimal cost (same grid, same model)."""
    free = solved(OPTIONS.replace(swing_clearance=None))
    assert cleared.solution.result.objective > free.solution.result.objective + 1.0
