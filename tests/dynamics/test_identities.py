"""Identities between our own algorithms (no external reference)."""

from __future__ import annotations

import numpy as np
from dynamics_helpers import assert_close, random_state

from gaitopt.dynamics import (
    aba,
    angular_momentum,
    center_of_mass,
    crba,
    gravity_forces,
    inverse_mass_times,
    kinetic_energy,
    linear_momentum,
    point_jacobian,
    point_position,
    point_velocity,
    potential_energy,
    rnea,
)
from gaitopt.robot import RobotModel


def test_aba_inverts_rnea(model: RobotModel) -> None:
    rng = np.random.default_rng(40)
    for _ in range(100):
        q, qd, qdd = random_state(rng, model.nq)
        tau = rnea(model, q, qd, qdd)
        assert_close(aba(model, q, qd, tau), qdd, rtol=1e-9, what="aba(rnea(a))")


def test_mass_matrix_identities(model: RobotModel) -> None:
    rng = np.random.default_rng(41)
    for _ in range(30):
        q, qd, qdd = random_state(rng, model.nq)
        m = crba(model, q)
        assert_close(m, m.T, rtol=1e-14, what="symmetric")
        assert np.all(np.linalg.eigvalsh(m) > 0.0)
        # rnea is affine in qdd with slope M
        assert_close(rnea(model, q, qd, qdd) - rnea(model, q, qd, 0 * qdd), m @ qdd,
                     what="M qdd")
        assert_close(inverse_mass_times(model, q, qdd), np.linalg.solve(m, qdd), what="M^-1")
        assert np.isclose(kinetic_energy(model, q, qd), 0.5 * qd @ m @ qd, rtol=1e-12)


def test_jacobian_is_derivative_of_position(model: RobotModel) -> None:
    rng = np.random.default_rng(42)
    link, p = len(model.links) - 1, (0.3, 0.05)
    for _ in range(10):
        q, qd, _ = random_state(rng, model.nq)
        jac = point_jacobian(model, q, link, p)
        h = 1e-6
        fd = np.column_stack([(point_position(model, q + h * e, link, p)
                               - point_position(model, q - h * e, link, p)) / (2 * h)
                              for e in np.eye(model.nq)])
        assert_close(jac, fd, rtol=1e-8, what="dp/dq")
        assert_close(point_velocity(model, q, qd, link, p), jac @ qd, what="v = J qd")


def test_momentum_and_gravity(model: RobotModel) -> None:
    rng = np.random.default_rng(43)
    total = model.total_mass
    g = np.asarray(model.gravity)
    for _ in range(10):
        q, qd, _ = random_state(rng, model.nq)
        # Gravity generalized force = -dV/dq (finite differences of the potential).
        h = 1e-6
        dv = np.array([(potential_energy(model, q + h * e) - potential_energy(model, q - h * e))
                       / (2 * h) for e in np.eye(model.nq)])
        assert_close(gravity_forces(model, q), dv, rtol=1e-7, what="G = dV/dq")
        # Linear momentum = m v_com; the base x, y generalized gravity = m g.
        h_com = (center_of_mass(model, q + 1e-7 * qd) - center_of_mass(model, q - 1e-7 * qd))
        assert_close(linear_momentum(model, q, qd), total * h_com / 2e-7, rtol=1e-6)
        assert_close(gravity_forces(model, q)[:2], -total * g, rtol=1e-12)
        # Angular momentum transforms like a moment: L_P = L_O - (P - O) x p.
        p = np.array([0.4, -0.2])
        lin = linear_momentum(model, q, qd)
        assert np.isclose(angular_momentum(model, q, qd, p),
                          angular_momentum(model, q, qd) - (p[0] * lin[1] - p[1] * lin[0]),
                          rtol=1e-12, atol=1e-12)
