"""The built-in ``adult-point-feet`` is the ``seven-link`` body with its feet fused at ankle
angle 0: same mass matrix, gravity forces and sole points, checked against the seven-link
model's own dynamics (not against the numbers typed into the file)."""

from __future__ import annotations

import numpy as np
import pytest

from gaitopt.dynamics.crba import crba
from gaitopt.dynamics.kinematics import contact_position
from gaitopt.dynamics.rnea import gravity_forces
from gaitopt.robot import RobotModel, builtin_names, load_model


@pytest.fixture(scope="module")
def models() -> tuple[RobotModel, RobotModel]:
    return load_model("adult-point-feet"), load_model("seven-link")


def locked(point_feet: RobotModel, feet: RobotModel, q5: np.ndarray) -> np.ndarray:
    """The seven-link coordinates of the five-link ``q5`` with both ankles at 0."""
    by_name = dict(zip(point_feet.coordinate_names, q5, strict=True))
    return np.array([by_name.get(n, 0.0) for n in feet.coordinate_names])


def rows(point_feet: RobotModel, feet: RobotModel) -> list[int]:
    return [feet.coordinate_names.index(n) for n in point_feet.coordinate_names]


def test_listed_with_the_same_total_mass(models: tuple[RobotModel, RobotModel]) -> None:
    point_feet, feet = models
    assert "adult-point-feet" in builtin_names()
    assert point_feet.total_mass == pytest.approx(feet.total_mass, rel=1e-12)


@pytest.mark.parametrize("seed", range(5))
def test_mass_matrix_and_gravity_equal_the_locked_seven_link(
        models: tuple[RobotModel, RobotModel], seed: int) -> None:
    point_feet, feet = models
    rng = np.random.default_rng(seed)
    q5 = rng.uniform(-1.0, 1.0, point_feet.nq)
    q7 = locked(point_feet, feet, q5)
    k = rows(point_feet, feet)
    m5 = np.asarray(crba(point_feet, q5), dtype=float)
    m7 = np.asarray(crba(feet, q7), dtype=float)[np.ix_(k, k)]
    # the file rounds the fused COM and inertia to 1e-5: errors of order mass * 1e-5 m
    np.testing.assert_allclose(m5, m7, atol=2e-4)
    g5 = np.asarray(gravity_forces(point_feet, q5), dtype=float).ravel()
    g7 = np.asarray(gravity_forces(feet, q7), dtype=float).ravel()[k]
    np.testing.assert_allclose(g5, g7, atol=2e-3)


def test_tips_at_the_sole_below_the_ankles(models: tuple[RobotModel, RobotModel]) -> None:
    point_feet, feet = models
    q5 = np.random.default_rng(7).uniform(-1.0, 1.0, point_feet.nq)
    q7 = locked(point_feet, feet, q5)
    for leg in ("1", "2"):
        tip = np.asarray(contact_position(point_feet, q5, f"tip_{leg}"), dtype=float).ravel()
        # the sole point straight below the ankle, on the heel-toe line 0.0532 m in front
        # of the heel (the heel 0.0532 m behind the ankle, the toe 0.1463 m in front)
        heel, toe = (np.asarray(contact_position(feet, q7, f"{c}_{leg}"), dtype=float).ravel()
                     for c in ("heel", "toe"))
        sole = heel + (toe - heel) * 0.0532 / (0.0532 + 0.1463)
        np.testing.assert_allclose(tip, sole, atol=1e-12)
