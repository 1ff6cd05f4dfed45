"""Collision Algorithm (eq. 11) and the liftoff impulse."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from dynamics_helpers import assert_close, random_state, well_conditioned

from gaitopt.dynamics import (
    angular_momentum,
    contact_jacobian,
    contact_position,
    contact_velocity,
    crba,
    hip_link,
    impact,
    kinetic_energy,
    liftoff_impulse,
    link_frames,
)
from gaitopt.robot import RobotModel


def test_impact_stops_the_tips_and_loses_energy(model: RobotModel) -> None:
    rng = np.random.default_rng(30)
    names = [c.name for c in model.contacts]
    sets = [(n,) for n in names] + list(itertools.combinations(names, 2))
    for contacts in sets:
        for _ in range(20):
            q, qd_minus, _ = random_state(rng, model.nq, scale=2.0)
            if not well_conditioned(model, q, contacts):
                continue
            sol = impact(model, q, qd_minus, contacts)
            for c in contacts:
                assert_close(contact_velocity(model, q, sol.qd_plus, c), np.zeros(2),
                             what="tip velocity after")
            ke_minus = kinetic_energy(model, q, qd_minus)
            ke_plus = kinetic_energy(model, q, sol.qd_plus)
            assert ke_plus <= ke_minus * (1 + 1e-12)
            # Momentum balance: M (qd_plus - qd_minus) = J^T impulses.
            jac = contact_jacobian(model, q, contacts)
            assert_close(crba(model, q) @ (sol.qd_plus - qd_minus), jac.T @ sol.impulses,
                         rtol=1e-9, what="momentum jump")


def test_single_impact_conserves_angular_momentum_about_the_tip(model: RobotModel) -> None:
    rng = np.random.default_rng(31)
    for c in (cc.name for cc in model.contacts):
        for _ in range(20):
            q, qd_minus, _ = random_state(rng, model.nq, scale=2.0)
            p_tip = contact_position(model, q, c)
            sol = impact(model, q, qd_minus, [c])
            before = angular_momentum(model, q, qd_minus, p_tip)
            after = angular_momentum(model, q, sol.qd_plus, p_tip)
            assert after == pytest.approx(before, rel=1e-10, abs=1e-10)
            # ... and not about another point (the impulse has a moment there).
            other = angular_momentum(model, q, sol.qd_plus, p_tip + np.array([1.0, 0.0]))
            other_before = angular_momentum(model, q, qd_minus, p_tip + np.array([1.0, 0.0]))
            if abs(sol.impulses[1]) > 1e-6:
                assert other != pytest.approx(other_before, rel=1e-6)


def test_impact_with_a_held_tip_keeps_it_fixed(five_link: RobotModel) -> None:
    rng = np.random.default_rng(32)
    q = np.array([0.0, 0.95, 0.05, 0.35, -0.1, -0.3, -0.05])
    qd = rng.normal(size=7)
    # Make tip_1 stationary first (it is on the ground), then strike tip_2.
    qd = impact(five_link, q, qd, ["tip_1"]).qd_plus
    sol = impact(five_link, q, qd, ["tip_1", "tip_2"])
    assert_close(contact_velocity(five_link, q, sol.qd_plus, "tip_1"), np.zeros(2))
    assert_close(contact_velocity(five_link, q, sol.qd_plus, "tip_2"), np.zeros(2))
    assert sol.impulses.shape == (4,)


def test_liftoff_impulse(model: RobotModel) -> None:
    rng = np.random.default_rng(33)
    names = [c.name for c in model.contacts]
    for lifting, held in itertools.permutations(names, 2):
        for _ in range(10):
            q, qd, _ = random_state(rng, model.nq)
            if not well_conditioned(model, q, [held]):
                continue
            qd = impact(model, q, qd, [held]).qd_plus
            magnitude = float(rng.uniform(0.0, 20.0))
            sol = liftoff_impulse(model, q, qd, lifting, magnitude, [held])
            assert_close(contact_velocity(model, q, sol.qd_plus, held), np.zeros(2))
            # Along the leg axis from tip to hip, with the given magnitude.
            hip = link_frames(model, q)[hip_link(model, lifting)].origin
            axis = hip - contact_position(model, q, lifting)
            axis /= np.linalg.norm(axis)
            assert_close(sol.impulse_lifting, magnitude * axis, rtol=1e-12)
            # Momentum balance with both impulses.
            jac_l = contact_jacobian(model, q, [lifting])
            jac_h = contact_jacobian(model, q, [held])
            assert_close(crba(model, q) @ (sol.qd_plus - qd),
                         jac_l.T @ sol.impulse_lifting + jac_h.T @ sol.impulses_held,
                         what="momentum jump")
    # Zero magnitude changes nothing when the held tip is already still.
    q, qd, _ = random_state(rng, model.nq)
    qd = impact(model, q, qd, [names[1]]).qd_plus
    sol = liftoff_impulse(model, q, qd, names[0], 0.0, [names[1]])
    assert_close(sol.qd_plus, qd)


def test_liftoff_without_held_contacts(five_link: RobotModel) -> None:
    q = np.array([0.0, 0.95, 0.05, 0.35, -0.1, -0.3, -0.05])
    qd = np.zeros(7)
    sol = liftoff_impulse(five_link, q, qd, "tip_2", 5.0, ())
    assert sol.impulses_held.shape == (0,)
    jac = contact_jacobian(five_link, q, ["tip_2"])
    assert_close(crba(five_link, q) @ sol.qd_plus, jac.T @ sol.impulse_lifting)
