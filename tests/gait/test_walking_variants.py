"""The variants of the walking problem: each solves, is physically right (Pinocchio), and
differs from the default problem the way its option says.

Costs are compared with the default problem's optimum where one problem is a restriction
(or a relaxation) of the other: a restriction cannot do better, a relaxation cannot do worse
(up to the solver tolerance; both are local optima reached from the same continuation).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from gaitopt.analysis.metrics import gait_metrics
from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.formulations.reduced.physics import SINGLE, control_names
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from tests.gait.conftest import (
    Reference,
    SolveFn,
    assert_physics,
    periodicity_errors,
    recomputed_cost,
)

RefFn = Callable[..., Reference]
REL = 1e-6  # relative slack on cost comparisons (solver tolerance)


def _verified(gait: Gait) -> None:
    report = verify_gait(gait)
    assert report.passed, [(c.name, c.value) for c in report.checks if not c.passed]
    assert recomputed_cost(gait) == pytest.approx(gait.cost_value, rel=1e-9)


def test_ankle_off(solved: SolveFn, default_gait: Gait, reference: RefFn) -> None:
    gait = solved(GaitOptions.paper(ankle=False)).gait
    assert gait.success
    model = gait.model
    for ph in gait.phases:
        for name in ("ankle_1", "ankle_2"):
            assert np.all(ph.u[:, model.actuator_index(name)] == 0.0)
    # Ankle torques are extra freedom: the default (ankle) optimum is no worse.
    assert default_gait.cost_value <= gait.cost_value * (1 + REL)
    assert_physics(reference(model), gait)
    _verified(gait)


def test_impulse_off(solved: SolveFn, default_gait: Gait, reference: RefFn) -> None:
    gait = solved(GaitOptions.paper(impulse=False)).gait
    assert gait.success
    assert gait.parameters["liftoff_impulse"] == 0.0
    liftoff = next(e for e in gait.events if e.name == "liftoff")
    np.testing.assert_array_equal(liftoff.impulses["tip_1"], [0.0, 0.0])
    assert default_gait.cost_value <= gait.cost_value * (1 + REL)
    assert_physics(reference(gait.model), gait)
    _verified(gait)


def test_speed_free_finds_the_optimal_walk_near_the_papers(
        solved: SolveFn, default_gait: Gait, reference: RefFn) -> None:
    """The paper's globally optimal walk: about 12 m/min with a step of about 0.1 m. Its cost
    is below the cost at the given speeds 6, 12 and 30 m/min."""
    free = solved(GaitOptions.paper(speed=None)).gait
    assert free.success
    speed_m_min = free.speed * 60.0
    assert 9.0 <= speed_m_min <= 15.0, speed_m_min
    assert 0.07 <= free.step_length <= 0.14, free.step_length
    lo, hi = GaitOptions.paper().speed_bounds
    assert lo * 1.01 < free.speed < hi * 0.99  # an interior optimum, not a bound
    slow = solved(GaitOptions.paper(speed=0.1)).gait
    fast = solved(GaitOptions.paper(speed=0.5)).gait
    assert slow.success and fast.success
    for other in (slow, default_gait, fast):
        assert free.cost_value <= other.cost_value * (1 + REL), (other.speed, other.cost_value)
    assert slow.cost_value > 1.2 * free.cost_value and fast.cost_value > 1.2 * free.cost_value
    assert_physics(reference(free.model), free)
    _verified(free)


def test_step_length_fixed(solved: SolveFn, default_gait: Gait, reference: RefFn) -> None:
    gait = solved(GaitOptions.paper(step_length=0.15)).gait
    assert gait.success
    assert gait.step_length == pytest.approx(0.15, abs=1e-9)
    assert gait.parameters["step_time"] == pytest.approx(0.15 / 0.2)
    # The default step length is free: its optimum is no worse than a fixed step's.
    assert default_gait.cost_value <= gait.cost_value * (1 + REL)
    assert_physics(reference(gait.model), gait)  # includes tip 2 held at (0.15, 0)
    _verified(gait)


def test_step_time_fixed_with_the_speed_given_and_free(
        solved: SolveFn, default_gait: Gait, reference: RefFn) -> None:
    """A step time fixes the step length at a given speed (the same optimum as that step
    length) and, with the speed free, gives the optimal walk of that step time."""
    timed = solved(GaitOptions.paper(step_time=0.75)).gait
    by_length = solved(GaitOptions.paper(step_length=0.15)).gait
    assert timed.success and timed.step_length == pytest.approx(0.15, abs=1e-9)
    assert timed.cost_value == pytest.approx(by_length.cost_value, rel=1e-5)
    walk = solved(GaitOptions.paper(speed=None, step_time=0.8)).gait
    assert walk.success
    assert walk.parameters["step_time"] == pytest.approx(0.8, abs=1e-7)
    assert walk.step_length == pytest.approx(0.8 * walk.speed, abs=1e-7)
    # Constrained, it costs no less than the free optimum (whose step time is about 0.57 s)
    # nor more than the 12 m/min gait of the same step time.
    free = solved(GaitOptions.paper(speed=None)).gait
    assert walk.cost_value >= free.cost_value * (1 - REL)
    fixed_speed = solved(GaitOptions.paper(step_time=0.8)).gait
    assert walk.cost_value <= fixed_speed.cost_value * (1 + REL)
    assert_physics(reference(walk.model), walk)
    _verified(walk)


def test_multistart_finds_the_lower_branch_at_high_speed(solved: SolveFn,
                                                         reference: RefFn) -> None:
    """Without ankle torques at 45 m/min the cold solve ends on a long-step local optimum;
    the continuation in speed from 12 m/min that ``multistart`` adds reaches the short-step
    one, about 13 % cheaper (docs/results/benchmarks-gait.md), and ``multistart`` keeps it."""
    options = GaitOptions.paper(speed=0.75, ankle=False, impulse=False)
    single = solved(options).gait
    multi = solved(options.replace(multistart=True)).gait
    assert single.success and multi.success
    assert multi.cost_value < 0.95 * single.cost_value, (multi.cost_value, single.cost_value)
    assert multi.step_length < single.step_length
    names = [s["name"] for s in multi.solver["stages"]]
    assert names.count("relaxed contact") == 4  # three naive guesses at 45, one at 12 m/min
    assert names[-1] == "continuation 45.0 m/min"
    assert_physics(reference(multi.model), multi)
    _verified(multi)


def test_single_support_fraction_one_has_no_double_support(
        solved: SolveFn, reference: RefFn) -> None:
    """The single-support gait: tip 2 strikes, tip 1 leaves at that instant with no impulse,
    and the next step starts at once."""
    gait = solved(GaitOptions.paper(single_support_fraction=1.0)).gait
    assert gait.success
    assert [ph.name for ph in gait.phases] == [SINGLE]
    assert gait.parameters["single_support_time"] == pytest.approx(gait.step_time)
    strike, lift = (next(e for e in gait.events if e.name == n)
                    for n in ("heel_strike", "liftoff"))
    assert strike.t == lift.t == pytest.approx(gait.step_time)
    np.testing.assert_array_equal(lift.impulses["tip_1"], [0.0, 0.0])
    np.testing.assert_array_equal(lift.qd_before, lift.qd_after)
    ref = reference(gait.model)
    q = gait.phases[0].q[-1]
    # Tip 2 alone takes the impact: M dqd = J_2^T impulse, tip 2 at rest afterwards ...
    jump = ref.mass_matrix(q) @ (strike.qd_after - strike.qd_before)
    j2 = ref.contact_jacobian(q, "tip_2")
    np.testing.assert_allclose(jump, j2.T @ strike.impulses["tip_2"], atol=1e-9)
    np.testing.assert_allclose(j2 @ strike.qd_after, 0.0, atol=1e-9)
    assert strike.impulses["tip_2"][1] >= -1e-9
    # ... and the trailing tip 1 leaves the ground (does not move into it).
    v1 = ref.contact_jacobian(q, "tip_1") @ strike.qd_after
    assert v1[1] >= -1e-9
    acting = ("hip_1", "knee_1", "hip_2", "knee_2")
    state, control = periodicity_errors(gait, controls=acting)
    assert state < 1e-6 and control < 1e-6  # 10 x the solve's tol 1e-7
    assert_physics(ref, gait)
    _verified(gait)


def test_periodic_states_only(solved: SolveFn, default_gait: Gait, reference: RefFn) -> None:
    gait = solved(GaitOptions.paper(periodic_controls=False)).gait
    assert gait.success
    acting = control_names(gait.model, SINGLE, ankle=True)
    state, control = periodicity_errors(gait, controls=acting)
    assert state < 1e-6
    # Dropping control periodicity relaxes the problem, and the optimum uses that freedom.
    assert control > 1e-2
    assert gait.cost_value <= default_gait.cost_value * (1 - 1e-3)
    assert_physics(reference(gait.model), gait)
    _verified(gait)


MU = 0.3


def _tangential_excess(gait: Gait, mu: float) -> float:
    """Largest |fx| - mu fy over every knot and tip in contact (N): <= 0 inside the cone."""
    return max(float(np.max(np.abs(f[:, 0]) - mu * f[:, 1]))
               for ph in gait.phases for f in ph.contact_forces.values())


def test_friction_cone_holds_at_every_knot(solved: SolveFn, default_gait: Gait,
                                           reference: RefFn) -> None:
    gait = solved(GaitOptions.paper(friction=MU)).gait
    assert gait.success
    assert _tangential_excess(default_gait, MU) > 1.0  # the default gait is outside the cone
    assert _tangential_excess(gait, MU) <= 1e-6
    assert default_gait.cost_value <= gait.cost_value * (1 + REL)  # a restriction
    assert_physics(reference(gait.model), gait)
    _verified(gait)


def test_friction_cone_gait_needs_no_more_friction_than_mu(solved: SolveFn) -> None:
    gait = solved(GaitOptions.paper(friction=MU)).gait
    assert gait_metrics(gait).friction_required <= MU * (1 + 1e-3)


def test_ankle_optimum_is_no_worse_than_without_ankles_at_6_m_min(solved: SolveFn) -> None:
    ankle = solved(GaitOptions.paper(speed=0.1)).gait
    plain = solved(GaitOptions.paper(speed=0.1, ankle=False)).gait
    assert ankle.success and plain.success
    assert ankle.cost_value <= plain.cost_value * (1 + REL)
