"""Unactuated simulations conserve energy (and momentum where they should)."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from gaitopt.dynamics import (
    aba,
    angular_momentum,
    center_of_mass,
    contact_dynamics,
    contact_position,
    contact_velocity,
    impact,
    linear_momentum,
    total_energy,
)
from gaitopt.robot import RobotModel

RTOL = ATOL = 1e-10


def test_free_flight_conserves_energy_and_momentum(five_link: RobotModel) -> None:
    model = five_link
    nq = model.nq
    q0 = np.array([0.0, 1.0, 0.2, 0.5, -0.6, -0.4, -0.2])
    qd0 = np.array([1.0, 2.0, -1.0, 3.0, -2.0, 1.5, 2.5])
    zero = np.zeros(nq)

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[nq:], aba(model, x[:nq], x[nq:], zero)])

    sol = solve_ivp(rhs, (0.0, 0.5), np.concatenate([q0, qd0]), method="DOP853",
                    rtol=RTOL, atol=ATOL, dense_output=False)
    assert sol.success
    e = [total_energy(model, x[:nq], x[nq:]) for x in sol.y.T]
    assert np.ptp(e) < 1e-7 * max(1.0, abs(e[0]))
    # Angular momentum about the (falling) centre of mass is constant, and the linear
    # momentum changes by m g t.
    lc = [angular_momentum(model, x[:nq], x[nq:], center_of_mass(model, x[:nq]))
          for x in sol.y.T]
    assert np.ptp(lc) < 1e-7
    p_end = linear_momentum(model, sol.y[:nq, -1], sol.y[nq:, -1])
    p_start = linear_momentum(model, q0, qd0)
    expected = p_start + model.total_mass * np.asarray(model.gravity) * sol.t[-1]
    assert np.allclose(p_end, expected, atol=1e-6)
    # A wrong sign of the bias forces would break this (sanity: energy is not trivially flat).
    assert np.ptp([x[1] for x in sol.y.T]) > 0.1


def test_pivoting_on_a_pinned_tip_conserves_energy(five_link: RobotModel) -> None:
    model = five_link
    nq = model.nq
    q0 = np.array([0.0, 0.95, 0.1, 0.2, -0.3, -0.5, -0.4])
    qd0 = impact(model, q0, np.array([0.8, 0.0, -0.5, 1.0, 0.5, -1.0, 0.7]), ["tip_1"]).qd_plus
    zero = np.zeros(nq)
    p_pin = contact_position(model, q0, "tip_1")

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[nq:], contact_dynamics(model, x[:nq], x[nq:], zero,
                                                        ["tip_1"]).qdd])

    sol = solve_ivp(rhs, (0.0, 0.4), np.concatenate([q0, qd0]), method="DOP853",
                    rtol=RTOL, atol=ATOL)
    assert sol.success
    e = [total_energy(model, x[:nq], x[nq:]) for x in sol.y.T]
    assert np.ptp(e) < 1e-7 * abs(e[0])
    # The tip stays where it was pinned, the body moves.
    x_end = sol.y[:, -1]
    assert np.allclose(contact_position(model, x_end[:nq], "tip_1"), p_pin, atol=1e-7)
    assert np.allclose(contact_velocity(model, x_end[:nq], x_end[nq:], "tip_1"), 0, atol=1e-7)
    assert np.linalg.norm(x_end[:nq] - q0) > 0.05
