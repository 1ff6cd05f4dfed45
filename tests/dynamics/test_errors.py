"""Bad inputs give clear, specific errors."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import gaitopt.dynamics as dyn
from gaitopt.dynamics import functions
from gaitopt.robot import RobotModel


def test_wrong_vector_length(five_link: RobotModel) -> None:
    with pytest.raises(ValueError, match=r"q must have 7 entries \(x, y, torso, hip_1"):
        dyn.crba(five_link, np.zeros(6))
    with pytest.raises(ValueError, match="qd must have 7 entries"):
        dyn.aba(five_link, np.zeros(7), np.zeros(8), np.zeros(7))
    with pytest.raises(ValueError, match="tau must have 7 entries"):
        dyn.contact_dynamics(five_link, np.zeros(7), np.zeros(7), np.zeros(6), ["tip_1"])
    with pytest.raises(ValueError, match=r"u must have 6 entries \(hip_1, knee_1, ankle_1"):
        dyn.generalized_forces(five_link, np.zeros(7), np.zeros(7))
    with pytest.raises(ValueError, match="q must be a vector of 7 entries.*6x1 CasADi SX"):
        dyn.crba(five_link, ca.SX.sym("q", 6))
    with pytest.raises(ValueError, match="point_local must have 2 entries"):
        dyn.point_position(five_link, np.zeros(7), "torso", (0.0, 0.1, 0.0))


def test_non_finite_input(five_link: RobotModel) -> None:
    q = np.zeros(7)
    q[4] = np.nan
    with pytest.raises(ValueError, match=r"q\[4\] = nan is not finite"):
        dyn.rnea(five_link, q, np.zeros(7), np.zeros(7))


def test_unknown_names(five_link: RobotModel) -> None:
    q = np.zeros(7)
    with pytest.raises(ValueError, match="no contact point 'tip_3' .*known: tip_1, tip_2"):
        dyn.contact_dynamics(five_link, q, q, q, ["tip_3"])
    with pytest.raises(ValueError, match="no contact point 'foot'"):
        dyn.impact(five_link, q, q, ["foot"])
    with pytest.raises(ValueError, match="no contact point 'x'"):
        functions.impact_function(five_link, ["x"])
    with pytest.raises(KeyError, match="no link 'arm'"):
        dyn.point_position(five_link, q, "arm", (0.0, 0.0))
    with pytest.raises(ValueError, match=r"link must be a link name or an index in 0\.\.4"):
        dyn.point_position(five_link, q, 5, (0.0, 0.0))
    with pytest.raises(ValueError, match="must be distinct"):
        dyn.impact(five_link, q, q, ["tip_1", "tip_1"])
    with pytest.raises(ValueError, match="contacts_held: .*no contact point 'tip'"):
        dyn.actuation_matrix(five_link, q, ["tip"])
    with pytest.raises(ValueError, match="inputs must be 'tau'"):
        functions.forward_dynamics_function(five_link, inputs="v")  # type: ignore[arg-type]


def test_liftoff_arguments(five_link: RobotModel) -> None:
    q = np.array([0.0, 0.95, 0.05, 0.35, -0.1, -0.3, -0.05])
    qd = np.zeros(7)
    with pytest.raises(ValueError, match=r"liftoff magnitude must be >= 0 N s.*got -1\.0"):
        dyn.liftoff_impulse(five_link, q, qd, "tip_2", -1.0, ["tip_1"])
    with pytest.raises(ValueError, match="cannot also be held"):
        dyn.liftoff_impulse(five_link, q, qd, "tip_2", 1.0, ["tip_2"])
    with pytest.raises(ValueError, match="lifting: .*no contact point 'tip_9'"):
        dyn.liftoff_impulse(five_link, q, qd, "tip_9", 1.0)


def test_singular_constraints_are_reported(five_link: RobotModel) -> None:
    # Both legs straight down from the hip: both tips at the same point, J M^-1 J^T singular.
    q = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    with pytest.raises(dyn.SingularSystemError, match="J M\\^-1 J\\^T of contacts tip_1, "
                                                      "tip_2 is singular"):
        dyn.contact_dynamics(five_link, q, np.zeros(7), np.zeros(7), ["tip_1", "tip_2"])
