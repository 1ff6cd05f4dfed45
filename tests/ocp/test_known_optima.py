"""Problems with analytic optima, solved to tight tolerance by both Hermite-Simpson forms."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import problems as P
import pytest

from gaitopt.ocp import Linkage, Phase, Problem, transcribe


@pytest.fixture(params=["hermite-simpson", "hermite-simpson-separated"])
def hs(request: pytest.FixtureRequest) -> str:
    """Both forms of Hermite-Simpson: compressed (DIRCOL's) and separated."""
    return str(request.param)


def test_double_integrator_min_energy_is_exact(hs: str) -> None:
    res = transcribe(P.double_integrator(10), method=hs).solve()
    assert res.success, res.summary()
    assert res.objective == pytest.approx(12.0, abs=1e-9)
    ph = res.phase("move")
    t = ph.t
    np.testing.assert_allclose(ph.state("s"), 3 * t**2 - 2 * t**3, atol=1e-10)
    np.testing.assert_allclose(ph.state("v"), 6 * t - 6 * t**2, atol=1e-10)
    np.testing.assert_allclose(ph.control("a"), 6 - 12 * t, atol=1e-9)
    # Between knots: cubic Hermite states and linear controls reproduce the exact solution.
    tt = np.linspace(0, 1, 101)
    np.testing.assert_allclose(ph.x_at(tt)[:, 0], 3 * tt**2 - 2 * tt**3, atol=1e-10)
    np.testing.assert_allclose(ph.u_at(tt)[:, 0], 6 - 12 * tt, atol=1e-9)
    np.testing.assert_allclose(ph.xdot_at(tt)[:, 0], 6 * tt - 6 * tt**2, atol=1e-9)
    # xdot at knots is the dynamics (v, a).
    np.testing.assert_allclose(ph.xdot, np.column_stack([ph.state("v"), ph.control("a")]))
    assert res.max_error < 1e-10
    assert res.constraint_violation < 1e-9


def test_brachistochrone_time_and_path_match_the_cycloid(hs: str) -> None:
    xf, yf = 1.0, 0.6
    res = transcribe(P.brachistochrone(xf, yf, intervals=30), method=hs).solve(
        P.brachistochrone_guess(xf, yf))
    assert res.success, res.summary()
    R, _, T = P.cycloid(xf, yf)
    assert res.objective == pytest.approx(T, rel=1e-6)
    ph = res.phase("slide")
    assert ph.duration == pytest.approx(T, rel=1e-6)
    phi = ph.t * math.sqrt(P.G / R)
    np.testing.assert_allclose(ph.state("x"), R * (phi - np.sin(phi)), atol=2e-5)
    np.testing.assert_allclose(ph.state("y"), R * (1 - np.cos(phi)), atol=2e-5)
    np.testing.assert_allclose(ph.state("v"), np.sqrt(2 * P.G * ph.state("y")), atol=2e-5)


def test_free_final_time_optimum(hs: str) -> None:
    res = transcribe(P.free_time(10), method=hs).solve()
    assert res.success, res.summary()
    assert res.phase(0).duration == pytest.approx(math.sqrt(6.0), rel=1e-8)
    assert res.objective == pytest.approx(8.0 / math.sqrt(6.0), rel=1e-9)


def test_two_phase_jump_matches_hand_derived_optimum(hs: str) -> None:
    res = transcribe(P.two_phase_jump(6), method=hs).solve()
    assert res.success, res.summary()
    assert res.objective == pytest.approx(60.0 / 13.0, rel=1e-9)
    before, after = res.phase("before"), res.phase("after")
    assert before.x[-1] == pytest.approx([11 / 13, 12 / 13], abs=1e-8)
    assert after.x[0] == pytest.approx([11 / 13, -6 / 13], abs=1e-8)
    assert after.t0 == pytest.approx(before.tf)
    assert after.tf == pytest.approx(2.0)


def test_jump_between_phases_of_different_state_dimension(hs: str) -> None:
    # Phase 1: double integrator (s, v) from rest, T = 1; phase 2: single integrator s' = w,
    # T = 1, ending at s = 1; jump s+ = s-. Cost int a^2 + int w^2.
    # J(s, v) = 12 (s - v/2)^2 + v^2 + (1 - s)^2; dJ/dv = 0 gives v = 3 s / 2, so
    # J = 3 s^2 + (1 - s)^2, minimal at s = 1/4: J* = 3/4.
    first = Phase("first", ["s", "v"], ["a"], P.double_integrator_dynamics, 1.0,
                  initial_state={"s": 0.0, "v": 0.0}, lagrange=P.energy, intervals=5)
    second = Phase("second", ["s"], ["w"], lambda x, u, p, t: u[0], 1.0,
                   final_state={"s": 1.0}, lagrange=lambda x, u, p, t: u[0] ** 2,
                   intervals=3)
    prob = Problem([first, second], linkages=[
        Linkage("first", "second", jump=lambda xf, uf, p: xf[0])])
    res = transcribe(prob, method=hs).solve()
    assert res.success, res.summary()
    assert res.objective == pytest.approx(0.75, rel=1e-9)
    assert res.phase("first").x[-1] == pytest.approx([0.25, 0.375], abs=1e-8)


def test_periodic_ratio_cost_optimum_and_linkages(hs: str) -> None:
    res = transcribe(P.periodic_ratio(c=4.0), method=hs).solve()
    assert res.success, res.summary()
    assert res.objective == pytest.approx(4.0, rel=1e-8)
    assert res.parameters["vbar"] == pytest.approx(2.0, rel=1e-6)
    first, second = res.phase("first"), res.phase("second")
    np.testing.assert_allclose(first.state("v"), 2.0, atol=1e-6)
    np.testing.assert_allclose(second.control("a"), 2.0, atol=1e-6)
    # Durations are the parameter expressions T_i = D / (2 vbar).
    assert first.duration == pytest.approx(0.25, rel=1e-6)
    assert second.tf - first.t0 == pytest.approx(0.5, rel=1e-6)
    assert second.state("s")[-1] - first.state("s")[0] == pytest.approx(1.0, abs=1e-9)


def test_path_constraint_active_at_knots_and_midpoints(hs: str) -> None:
    limit = 1.2
    res = transcribe(P.with_path_constraint(20, limit), method=hs).solve()
    assert res.success, res.summary()
    ph = res.phase(0)
    speed = ph.path["speed"][:, 0]
    np.testing.assert_allclose(speed, ph.state("v"))
    assert speed.max() == pytest.approx(limit, abs=1e-7)
    # Imposed at midpoints too: the interpolant at midpoints respects the cap.
    mid = 0.5 * (ph.t[:-1] + ph.t[1:])
    assert ph.x_at(mid)[:, 1].max() <= limit + 1e-7
    if ph.x_mid is not None:  # separated: imposed on the midpoint variables, active there
        assert ph.x_mid[:, 1].max() == pytest.approx(limit, abs=1e-7)
        np.testing.assert_allclose(ph.x_mid, ph.x_at(mid), atol=1e-8)
    assert res.objective > 12.0  # the cap costs energy


def test_sx_function_inside_dynamics_and_cse(hs: str) -> None:
    # Dynamics calling an SX Function twice (the same subexpression) still solve correctly.
    z = ca.SX.sym("z", 2)
    acc = ca.Function("acc", [z], [z[1] * 1.0])
    ph = Phase("move", ["s", "v"], ["a"],
               lambda x, u, p, t: ca.vertcat(x[1], acc(ca.vertcat(x[0], u[0]))), 1.0,
               initial_state={"s": 0.0, "v": 0.0}, final_state={"s": 1.0, "v": 0.0},
               lagrange=lambda x, u, p, t: acc(ca.vertcat(x[0], u[0])) ** 2, intervals=4)
    res = transcribe(Problem([ph]), method=hs).solve()
    assert res.objective == pytest.approx(12.0, abs=1e-9)
