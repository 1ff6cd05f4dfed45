"""The paper's default walking problem: it converges, and the saved gait is physically right.

Every check is independent of the solver's reduced dynamics and collocation: Pinocchio's
equations of motion, contact Jacobians and tip kinematics, the gait file's leg-swap
permutations, and a separate quadrature of the cost.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from gaitopt.gait.formulations.reduced.physics import DOUBLE, SINGLE, control_names
from gaitopt.gait.record.file import Gait
from tests.gait.conftest import (
    EOM_RTOL,
    Reference,
    Solved,
    assert_physics,
    contact_forces,
    eom_residuals,
    held_tip_errors,
    lowest_sample_normal_force,
    periodicity_errors,
    recomputed_cost,
)

RefFn = Callable[..., Reference]


def test_default_problem_converges_through_every_stage(default_solved: Solved) -> None:
    sol, gait = default_solved.solution, default_solved.gait
    assert sol.success and gait.success
    assert sol.failed_stage is None
    assert [s.success for s in sol.stages] == [True] * len(sol.stages)
    assert gait.solver["max_violation"] < 1e-6
    assert gait.speed == pytest.approx(0.2, abs=1e-9)  # 12 m/min, given
    # The optimal step at 12 m/min: the paper reports about 0.1 m.
    assert 0.05 < gait.step_length < 0.2
    assert gait.parameters["step_time"] == pytest.approx(gait.step_length / gait.speed)
    assert gait.parameters["single_support_time"] == pytest.approx(
        0.85 * gait.parameters["step_time"])
    assert [ph.name for ph in gait.phases] == [SINGLE, DOUBLE]
    assert [ph.t.size for ph in gait.phases] == [8, 5]
    assert np.isfinite(gait.cost_value) and gait.cost_value > 0.0


def test_nlp_size_is_the_knot_values_and_three_parameters(default_gait: Gait) -> None:
    """Compressed Hermite-Simpson: states and controls at the knots, plus L, v, P (the paper's
    DIRCOL NLP has 197 variables; see the docs for the difference)."""
    model = default_gait.model
    expected = 3
    for ph in default_gait.phases:
        controls = control_names(model, ph.name, ankle=True)
        expected += ph.t.size * (len(ph.state_names) + len(controls))
    assert default_gait.solver["variables"] == expected == 8 * (10 + 5) + 5 * (6 + 6) + 3


def test_every_knot_satisfies_pinocchio_equations_of_motion(
        default_gait: Gait, reference: RefFn) -> None:
    """M(q) qdd + h(q, qd) = B u + J_c^T f at all 8 + 5 knots with the saved values."""
    ref = reference(default_gait.model)
    for ph in default_gait.phases:
        res = eom_residuals(ref, ph)
        assert res.shape == (ph.t.size,)
        assert np.all(res < EOM_RTOL), (ph.name, res)


def test_equations_of_motion_check_detects_a_wrong_force(
        default_gait: Gait, reference: RefFn) -> None:
    """The residual is sensitive: 1 N off one saved contact force is seen."""
    ref = reference(default_gait.model)
    ph = default_gait.phases[1]
    forces = {c: np.array(f) for c, f in ph.contact_forces.items()}
    forces["tip_2"][2, 0] += 1.0
    bad = type(ph)(name=ph.name, contacts=ph.contacts, t=ph.t, q=ph.q, qd=ph.qd, qdd=ph.qdd,
                   u=ph.u, contact_forces=forces, state_names=ph.state_names, x=ph.x,
                   xdot=ph.xdot)
    res = eom_residuals(ref, bad)
    assert res[2] > 1e-4 and np.all(np.delete(res, 2) < EOM_RTOL)


def test_ankle_actuation_acts_on_torso_hip_and_knee_of_its_leg(
        default_gait: Gait, reference: RefFn) -> None:
    """The Pinocchio actuation matrix used above has the structure of docs/conventions.md §4."""
    model = default_gait.model
    ref = reference(model)
    q = default_gait.phases[1].q[0]
    b = ref.actuation(q, ("tip_1", "tip_2"))
    names = model.coordinate_names
    for leg in ("1", "2"):
        col = b[:, model.actuator_index(f"ankle_{leg}")]
        expected = [1.0 if n in ("torso", f"hip_{leg}", f"knee_{leg}") else 0.0 for n in names]
        np.testing.assert_allclose(col, expected, atol=1e-12)
        hip = b[:, model.actuator_index(f"hip_{leg}")]
        np.testing.assert_allclose(hip, np.eye(model.nq)[names.index(f"hip_{leg}")])
    b_air = ref.actuation(q, ("tip_1",))
    assert not np.any(b_air[:, model.actuator_index("ankle_2")])


def test_held_tips_stay_at_their_points(default_gait: Gait, reference: RefFn) -> None:
    """Tip 1 at (0, 0) in both phases, tip 2 at (L, 0) in double support; zero velocity and
    acceleration (Pinocchio frame kinematics)."""
    err = held_tip_errors(reference(default_gait.model), default_gait)
    assert err["position"] < 1e-10
    assert err["velocity"] < 1e-10
    assert err["acceleration"] < 1e-8


def test_swing_tip_lands_at_step_length(default_gait: Gait, reference: RefFn) -> None:
    ref = reference(default_gait.model)
    ss = default_gait.phases[0]
    p, _, _ = ref.tip_kinematics(ss.q[-1], ss.qd[-1], ss.qdd[-1], "tip_2")
    np.testing.assert_allclose(p, [default_gait.step_length, 0.0], atol=1e-9)
    for k in range(ss.t.size - 1):  # above the ground at every knot before landing
        p, _, _ = ref.tip_kinematics(ss.q[k], ss.qd[k], ss.qdd[k], "tip_2")
        assert p[1] >= -1e-9


def test_normal_forces_and_impulses_are_non_negative(default_gait: Gait) -> None:
    for ph in default_gait.phases:
        for c, f in ph.contact_forces.items():
            assert np.all(f[:, 1] >= -1e-6), (ph.name, c, f[:, 1])
    for e in default_gait.events:
        for c, i in e.impulses.items():
            assert i[1] >= -1e-8, (e.name, c, i)


def test_events_conserve_momentum_with_their_impulses(
        default_gait: Gait, reference: RefFn) -> None:
    """Heel strike and liftoff: M(q) (qd_after - qd_before) = sum_c J_c^T impulse_c, and every
    tip held after the event has zero velocity; the liftoff impulse is P along leg 1, tip to
    hip."""
    gait = default_gait
    ref = reference(gait.model)
    events = {e.name: e for e in gait.events}
    ends = {"heel_strike": gait.phases[0].q[-1], "liftoff": gait.phases[1].q[-1]}
    held_after = {"heel_strike": ("tip_1", "tip_2"), "liftoff": ("tip_2",)}
    for name, q in ends.items():
        e = events[name]
        jump = ref.mass_matrix(q) @ (e.qd_after - e.qd_before)
        applied = sum((ref.contact_jacobian(q, c).T @ i for c, i in e.impulses.items()),
                      start=np.zeros(gait.model.nq))
        np.testing.assert_allclose(jump, applied, atol=1e-9)
        for c in held_after[name]:
            np.testing.assert_allclose(ref.contact_jacobian(q, c) @ e.qd_after, 0.0, atol=1e-9)
    # The velocity after the heel strike starts double support.
    np.testing.assert_allclose(events["heel_strike"].qd_after, gait.phases[1].qd[0], atol=1e-9)
    q = gait.phases[1].q[-1]
    tip, _, _ = ref.tip_kinematics(q, np.zeros(7), np.zeros(7), "tip_1")
    axis = (q[:2] - tip) / np.linalg.norm(q[:2] - tip)
    p = gait.parameters["liftoff_impulse"]
    np.testing.assert_allclose(events["liftoff"].impulses["tip_1"], p * axis, atol=1e-9)


def test_periodic_with_legs_swapped(default_gait: Gait) -> None:
    """The state after liftoff, legs relabelled and moved back one step, is the first knot;
    so are the controls (periodic controls, the paper's default)."""
    acting = control_names(default_gait.model, SINGLE, ankle=True)
    state, control = periodicity_errors(default_gait, controls=acting)
    # the solve meets the periodicity constraints to its tolerance (tol 1e-7); 10 x that
    assert state < 1e-6
    assert control < 1e-6


def test_periodicity_check_sees_a_broken_step(default_gait: Gait) -> None:
    """The same check fails on a gait with the legs not swapped (the identity relabelling
    would mean the same leg always stands)."""
    first, last = default_gait.phases[0], default_gait.phases[-1]
    q_next = last.q[-1].copy()
    q_next[0] -= default_gait.step_length
    assert np.max(np.abs(q_next - first.q[0])) > 1e-2


def test_cost_recomputed_from_the_file_equals_the_reported_one(default_gait: Gait) -> None:
    assert recomputed_cost(default_gait) == pytest.approx(default_gait.cost_value, rel=1e-9)
    assert default_gait.cost["formula"].startswith("energy per metre")


def test_assert_physics_helper_accepts_the_default_gait(
        default_gait: Gait, reference: RefFn) -> None:
    assert_physics(reference(default_gait.model), default_gait)


def test_saved_forces_are_pinocchios_contact_forces(default_gait: Gait,
                                                    reference: RefFn) -> None:
    """Forward contact dynamics from the saved (q, qd, u) with Pinocchio's M, h, J gives the
    saved contact forces at every knot (and the dense samples have no negative normal
    force)."""
    ref = reference(default_gait.model)
    for ph in default_gait.phases:
        for k in range(ph.t.size):
            f = contact_forces(ref, ph.q[k], ph.qd[k], ph.u[k], ph.contacts)
            saved = np.array([ph.contact_forces[c][k] for c in ph.contacts])
            np.testing.assert_allclose(f, saved, atol=1e-7 * default_gait.model.total_mass)
    assert lowest_sample_normal_force(ref, default_gait) >= -1e-3
