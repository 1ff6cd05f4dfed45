"""The Reduced Dynamics Algorithm: coordinates round-trip, held tips stay put, and integrating
the reduced system reproduces the full constrained system (paper appendices 2-3)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gaitopt.dynamics.actuation import generalized_forces
from gaitopt.dynamics.contact import contact_dynamics
from gaitopt.dynamics.kinematics import contact_position, contact_velocity
from gaitopt.dynamics.reduced import (
    ReachError,
    double_support_coordinates,
    double_support_dynamics,
    double_support_state,
    leg_inverse_kinematics,
    single_support_coordinates,
    single_support_dynamics,
    single_support_state,
)
from gaitopt.robot import load_model, model_from_dict
from gaitopt.robot.biped import BipedStructureError, biped_of, reduced_biped

MODEL = load_model("five-link")
LEGS = biped_of(MODEL).legs
FRONT = (0.25, 0.0)


def random_single(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    z = np.array([rng.uniform(0.6, 0.99), rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3),
                  rng.uniform(-1.0, 1.0), rng.uniform(-1.5, -0.05)])
    return z, rng.normal(size=5)


def random_double(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    z = np.array([rng.uniform(0.85, 0.99), rng.uniform(-0.2, -0.05), rng.uniform(-0.3, 0.3)])
    return z, rng.normal(size=3) * 0.3


@pytest.mark.parametrize("stance", [0, 1])
def test_single_support_state_holds_the_stance_tip_and_round_trips(stance: int) -> None:
    rng = np.random.default_rng(1 + stance)
    tip = (0.3, 0.0)
    for _ in range(50):
        z, zd = random_single(rng)
        q, qd = single_support_state(MODEL, stance, z, zd, tip)
        contact = LEGS[stance].contact
        np.testing.assert_allclose(contact_position(MODEL, q, contact), tip, atol=1e-12)
        np.testing.assert_allclose(contact_velocity(MODEL, q, qd, contact), 0.0, atol=1e-12)
        assert q[LEGS[stance].knee_index] < 0.0  # the knee bends backwards
        z2, zd2 = single_support_coordinates(MODEL, stance, q, qd, tip)
        np.testing.assert_allclose(z2, z, atol=1e-12)
        np.testing.assert_allclose(zd2, zd, atol=1e-12)


def test_double_support_state_holds_both_tips_and_round_trips() -> None:
    rng = np.random.default_rng(3)
    for _ in range(50):
        z, zd = random_double(rng)
        q, qd = double_support_state(MODEL, 0, z, zd, (0.0, 0.0), FRONT)
        for leg, tip in zip(LEGS, ((0.0, 0.0), FRONT), strict=True):
            np.testing.assert_allclose(contact_position(MODEL, q, leg.contact), tip, atol=1e-12)
            np.testing.assert_allclose(contact_velocity(MODEL, q, qd, leg.contact), 0.0,
                                       atol=1e-12)
        z2, zd2 = double_support_coordinates(MODEL, 0, q, qd)
        np.testing.assert_allclose(z2, z, atol=1e-12)
        np.testing.assert_allclose(zd2, zd, atol=1e-12)


def test_inverse_kinematics_inverts_forward_kinematics() -> None:
    rng = np.random.default_rng(4)
    leg = LEGS[0]
    for _ in range(100):
        q = np.zeros(MODEL.nq)
        q[2] = rng.uniform(-0.5, 0.5)
        q[leg.hip_index] = rng.uniform(-1.0, 1.0)
        q[leg.knee_index] = rng.uniform(-2.4, -0.01)
        tip = contact_position(MODEL, q, leg.contact)
        joints = leg_inverse_kinematics(leg, [0.0, 0.0], [0.0, 0.0], list(tip), q[2], 0.0)
        assert joints.hip == pytest.approx(q[leg.hip_index], abs=1e-10)
        assert joints.knee == pytest.approx(q[leg.knee_index], abs=1e-10)


def test_out_of_reach_is_an_error_not_nan() -> None:
    with pytest.raises(ReachError, match="outside the leg's reach"):
        single_support_state(MODEL, 0, [1.05, 0.0, 0.0, 0.0, -0.2], np.zeros(5))
    with pytest.raises(ReachError, match="tip_2"):
        double_support_state(MODEL, 0, [0.95, 0.0, 0.0], np.zeros(3), (0.0, 0.0), (1.5, 0.0))


def _integrate_full(q0: np.ndarray, qd0: np.ndarray, u: np.ndarray, held: list[str],
                    duration: float) -> np.ndarray:
    n = MODEL.nq

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        q, qd = y[:n], y[n:]
        tau = generalized_forces(MODEL, q, u, held)
        return np.concatenate([qd, contact_dynamics(MODEL, q, qd, tau, held).qdd])

    sol = solve_ivp(rhs, (0.0, duration), np.concatenate([q0, qd0]), rtol=1e-11, atol=1e-12)
    return sol.y[:, -1]


def test_integrating_reduced_single_support_reproduces_the_full_constrained_motion() -> None:
    rng = np.random.default_rng(5)
    z0, zd0 = random_single(rng)
    zd0 *= 0.3
    u = rng.normal(size=MODEL.nu) * 5.0
    duration = 0.15

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        z, zd = y[:5], y[5:]
        q, _ = single_support_state(MODEL, 0, z, zd)
        tau = generalized_forces(MODEL, q, u, [LEGS[0].contact])
        return np.concatenate([zd, single_support_dynamics(MODEL, 0, z, zd, tau).zdd])

    reduced = solve_ivp(rhs, (0.0, duration), np.concatenate([z0, zd0]), rtol=1e-11,
                        atol=1e-12).y[:, -1]
    q_red, qd_red = single_support_state(MODEL, 0, reduced[:5], reduced[5:])
    q0, qd0 = single_support_state(MODEL, 0, z0, zd0)
    full = _integrate_full(q0, qd0, u, [LEGS[0].contact], duration)
    np.testing.assert_allclose(q_red, full[:MODEL.nq], atol=1e-7)
    np.testing.assert_allclose(qd_red, full[MODEL.nq:], atol=1e-6)


def test_integrating_reduced_double_support_reproduces_the_full_constrained_motion() -> None:
    rng = np.random.default_rng(6)
    z0, zd0 = random_double(rng)
    u = rng.normal(size=MODEL.nu) * 5.0
    held = [LEGS[0].contact, LEGS[1].contact]
    duration = 0.1

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        z, zd = y[:3], y[3:]
        q, _ = double_support_state(MODEL, 0, z, zd, (0.0, 0.0), FRONT)
        tau = generalized_forces(MODEL, q, u, held)
        sol = double_support_dynamics(MODEL, 0, z, zd, tau, (0.0, 0.0), FRONT)
        return np.concatenate([zd, sol.zdd])

    reduced = solve_ivp(rhs, (0.0, duration), np.concatenate([z0, zd0]), rtol=1e-11,
                        atol=1e-12).y[:, -1]
    q_red, qd_red = double_support_state(MODEL, 0, reduced[:3], reduced[3:], (0.0, 0.0), FRONT)
    q0, qd0 = double_support_state(MODEL, 0, z0, zd0, (0.0, 0.0), FRONT)
    full = _integrate_full(q0, qd0, u, held, duration)
    np.testing.assert_allclose(q_red, full[:MODEL.nq], atol=1e-7)
    np.testing.assert_allclose(qd_red, full[MODEL.nq:], atol=1e-6)


def test_symbolic_reduced_dynamics_equal_numeric_and_match_finite_differences() -> None:
    rng = np.random.default_rng(7)
    z_sym, zd_sym, tau_sym = ca.SX.sym("z", 5), ca.SX.sym("zd", 5), ca.SX.sym("tau", 7)
    sol = single_support_dynamics(MODEL, 0, z_sym, zd_sym, tau_sym)
    f = ca.Function("f", [z_sym, zd_sym, tau_sym], [sol.zdd])
    z, zd = random_single(rng)
    tau = rng.normal(size=7)
    numeric = single_support_dynamics(MODEL, 0, z, zd, tau).zdd
    np.testing.assert_allclose(np.asarray(f(z, zd, tau)).ravel(), numeric, rtol=1e-12,
                               atol=1e-12)
    jac = ca.Function("j", [z_sym, zd_sym, tau_sym], [ca.jacobian(sol.zdd, z_sym)])
    eps = 1e-6
    fd = np.column_stack([
        (np.asarray(f(z + eps * e, zd, tau)).ravel() - np.asarray(f(z - eps * e, zd, tau)).ravel())
        / (2 * eps) for e in np.eye(5)])
    np.testing.assert_allclose(np.asarray(jac(z, zd, tau)), fd, rtol=1e-5, atol=1e-5)


def test_a_model_without_two_legs_is_rejected_by_name() -> None:
    data = MODEL.to_dict()
    data["contacts"] = data["contacts"][:1]
    data["actuators"] = [a for a in data["actuators"] if a.get("contact") != "tip_2"]
    with pytest.raises(BipedStructureError, match="exactly two contact points"):
        biped_of(model_from_dict(data))


def test_the_biped_is_built_once_per_model() -> None:
    """Equal (immutable) models share one structure; a model that is no biped is refused at
    every request, not cached as a success."""
    five = load_model("five-link")
    assert biped_of(five) is biped_of(load_model("five-link"))
    assert reduced_biped(five) is reduced_biped(model_from_dict(five.to_dict()))
    data = five.to_dict()
    data["contacts"] = data["contacts"][:1]
    data["actuators"] = [a for a in data["actuators"] if a.get("contact") != "tip_2"]
    one_leg = model_from_dict(data)
    for _ in range(2):
        with pytest.raises(BipedStructureError, match="exactly two contact points"):
            biped_of(one_leg)


def test_the_base_coordinates_are_named_and_indexed_once() -> None:
    """``q = [x, y, base angle, joints...]``: the index constants match the names."""
    from gaitopt.robot.model import (
        BASE_ANGLE,
        BASE_COORDINATES,
        BASE_POSITION,
        BASE_X,
        BASE_Y,
    )

    model = load_model("five-link")
    names = model.coordinate_names
    assert (names[BASE_X], names[BASE_Y]) == BASE_COORDINATES[:2]
    assert names[BASE_ANGLE] == model.base.name
    assert tuple(names[BASE_POSITION]) == BASE_COORDINATES[:2]
