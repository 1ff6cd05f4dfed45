"""The control-rate term of the cost (``Phase.control_rate_weights``: ``r int u'^2 dt``, exact
``r sum (du)^2 / h`` on piecewise-linear controls) against analytic optima."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from gaitopt.ocp import Phase, Problem, ProblemError, transcribe
from gaitopt.ocp.nlp import control_rate_term

METHODS = ["hermite-simpson", "hermite-simpson-separated", "trapezoidal"]


def ramp(r: float, intervals: int) -> Problem:
    """x' = u on [0, 2] with u(0) = 0, u(2) = 1 and cost r int u'^2 dt: the optimum is the
    straight ramp u = t / 2, cost r / 2, on any grid."""
    return Problem(phases=[Phase(
        name="ramp", states=["x"], controls=["u"], duration=2.0,
        dynamics=lambda x, u, p, t: u[0], initial_state={"x": 0.0},
        initial_control={"u": 0.0}, final_control={"u": 1.0},
        control_rate_weights={"u": r}, intervals=intervals)])


def tracking(r: float, T: float, intervals: int) -> Problem:
    """min int (u - 1)^2 + r u'^2 dt on [0, T], u(0) = 0, u(T) free: u = 1 - cosh((T - t) /
    a) / cosh(T / a) with a = sqrt(r), cost a tanh(T / a)."""
    return Problem(phases=[Phase(
        name="track", states=["x"], controls=["u"], duration=T,
        dynamics=lambda x, u, p, t: u[0], initial_state={"x": 0.0},
        initial_control={"u": 0.0}, lagrange=lambda x, u, p, t: (u[0] - 1.0) ** 2,
        control_rate_weights={"u": r}, intervals=intervals)])


def test_the_term_is_the_exact_integral_of_piecewise_linear_controls() -> None:
    phase = ramp(1.0, 3).phases[0]
    t = np.array([0.0, 0.5, 1.25, 2.0])
    u = np.array([[0.0, 1.0, -0.5, 0.25]])
    expected = sum((u[0, k + 1] - u[0, k]) ** 2 / (t[k + 1] - t[k]) for k in range(3))
    got = float(control_rate_term(phase, ca.DM(u), ca.DM(np.diff(t)).T))
    assert got == pytest.approx(expected, rel=1e-15)
    assert control_rate_term(Phase(name="p", states=["x"], controls=["u"], duration=1.0,
                                   dynamics=lambda x, u, p, t: u[0]), ca.DM(u),
                             ca.DM(np.diff(t)).T) == 0.0


@pytest.mark.parametrize("method", METHODS)
def test_the_ramp_is_the_optimum_on_any_grid(method: str) -> None:
    res = transcribe(ramp(3.0, 7), method=method).solve()
    assert res.success, res.summary()
    assert res.objective == pytest.approx(1.5, rel=1e-6)
    ph = res.phase("ramp")
    np.testing.assert_allclose(ph.control("u"), ph.t / 2.0, atol=1e-6)


@pytest.mark.parametrize("method", ["hermite-simpson", "hermite-simpson-separated"])
def test_the_tracking_optimum_converges_at_second_order(method: str) -> None:
    r, T = 0.04, 1.0
    exact = math.sqrt(r) * math.tanh(T / math.sqrt(r))
    errors = []
    for n in (10, 20, 40):
        res = transcribe(tracking(r, T, n), method=method).solve()
        assert res.success, res.summary()
        errors.append(abs(res.objective - exact))
    assert errors[-1] < 1e-3 * exact
    orders = [math.log2(a / b) for a, b in zip(errors, errors[1:], strict=False)]
    assert all(1.8 < p < 2.2 for p in orders), orders


def test_a_negative_or_unknown_weight_is_refused() -> None:
    bad = ramp(-1.0, 3)
    with pytest.raises(ProblemError, match=r"control_rate_weights\['u'\] = -1.0: must be "
                                           r"finite and >= 0"):
        transcribe(bad, method="trapezoidal")
    unknown = Problem(phases=[Phase(name="p", states=["x"], controls=["u"], duration=1.0,
                                    dynamics=lambda x, u, p, t: u[0],
                                    control_rate_weights={"v": 1.0})])
    with pytest.raises(ProblemError, match="control_rate_weights: unknown name 'v'"):
        transcribe(unknown, method="trapezoidal")
