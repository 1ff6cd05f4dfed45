"""Costates from the defect multipliers (gaitopt.ocp.costate) against analytic costates.

Sign convention H = L + lambda^T f. The known answers: the free-end LQ problem of
``problems.free_end_lq`` (lambda from the Hamiltonian system, lambda(T) = 0), the fixed-end
``smooth_lq`` (H = x^2 + u^2 + lambda u: lambda = -2u = 2 cosh(2 - t) / sinh 2 > 0) and the
rest-to-rest double integrator (H = a^2 + l_s v + l_v a: l_s = -24, l_v = 24 t - 12, exact for
Hermite-Simpson, whose states are cubic there).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import problems as P
import pytest

from gaitopt.ocp import ProblemError, transcribe
from gaitopt.ocp.costate import costates, one_sided_costates

METHODS = ["trapezoidal", "hermite-simpson", "hermite-simpson-separated"]
GRIDS = (4, 8, 16, 32)
TOL = {"ipopt.tol": 1e-12}


@functools.cache
def free_end_errors(method: str) -> tuple[tuple[float, ...], ...]:
    """Largest knot errors of lambda, of H_u = u + lambda at all knots and at the inner knots
    on each grid of GRIDS."""
    lam_err, hu_err, hu_inner = [], [], []
    for n in GRIDS:
        tr = transcribe(P.free_end_lq(intervals=n), method=method, options=TOL)
        res = tr.solve()
        assert res.success, res.summary()
        ph = res.phase("lq")
        lam = costates(tr, res)["lq"][:, 0]
        _, exact = P.free_end_lq_solution(ph.t)
        lam_err.append(float(np.max(np.abs(lam - exact))))
        h_u = ph.u[:, 0] + lam  # H_u = L_u + f_u lambda
        hu_err.append(float(np.max(np.abs(h_u))))
        hu_inner.append(float(np.max(np.abs(h_u[1:-1]))))
    return tuple(lam_err), tuple(hu_err), tuple(hu_inner)


def orders(errors: tuple[float, ...]) -> list[float]:
    return [math.log2(errors[i] / errors[i + 1]) for i in range(len(errors) - 1)]


@pytest.mark.parametrize(("method", "order"), [("trapezoidal", 1.7), ("hermite-simpson", 3.5),
                                               ("hermite-simpson-separated", 3.5)])
def test_costate_error_falls_at_the_scheme_order(method: str, order: float) -> None:
    errors = free_end_errors(method)[0]
    # Measured (docs/ocp.md, "Costates"): 1.83-1.96 trapezoidal, 4.00 Hermite-Simpson.
    assert min(orders(errors)) > order, (errors, orders(errors))
    assert errors[-1] < (1e-3 if method == "trapezoidal" else 1e-7), errors


@pytest.mark.parametrize("method", METHODS)
def test_hamiltonian_is_stationary_in_the_control(method: str) -> None:
    # An independent check of lambda: H_u = u + lambda -> 0 at the knots, at O(h^2) inside
    # (for Hermite-Simpson too: the knot controls of its piecewise-linear control model are
    # second order, while its costates are fourth order) and at the end knots but O(h) there
    # for trapezoidal (its end controls balance lambda half an interval inside).
    _, hu, inner = free_end_errors(method)
    assert min(orders(inner)) > 1.7, (inner, orders(inner))
    assert min(orders(hu)) > (0.9 if method == "trapezoidal" else 1.7), (hu, orders(hu))
    assert inner[-1] < 5e-4, inner


@pytest.mark.parametrize("method", METHODS)
def test_sign_and_transversality(method: str) -> None:
    tr = transcribe(P.free_end_lq(intervals=16), method=method, options=TOL)
    res = tr.solve()
    lam = costates(tr, res)["lq"][:, 0]
    _, exact = P.free_end_lq_solution(res.phase("lq").t)
    assert np.all(exact[:-1] > 0.05) and np.all(lam[:-1] > 0.0)  # H = L + lambda f, not -
    assert abs(lam[-1]) < 1e-2  # lambda(T) = 0 at the free final state
    tr = transcribe(P.smooth_lq(16), method=method, options=TOL)
    res = tr.solve()
    t = res.phase("lq").t
    lam = costates(tr, res)["lq"][:, 0]
    np.testing.assert_allclose(lam, 2 * np.cosh(2 - t) / np.sinh(2), atol=2e-2)


@pytest.mark.parametrize("method", METHODS)
def test_vector_costates_by_state_order(method: str) -> None:
    tr = transcribe(P.double_integrator(8), method=method, options=TOL)
    res = tr.solve()
    t = res.phase("move").t
    exact = np.stack([np.full_like(t, -24.0), 24.0 * t - 12.0], axis=1)
    lam = costates(tr, res)["move"]
    atol = 1e-6 if method != "trapezoidal" else 2.0  # trapezoidal: O(h^2), 1.4 at h = 1/8
    np.testing.assert_allclose(lam, exact, atol=atol)


@pytest.mark.parametrize("method", METHODS)
def test_one_sided_estimates_agree_where_no_constraint_acts(method: str) -> None:
    tr = transcribe(P.free_end_lq(intervals=10), method=method, options=TOL)
    res = tr.solve()
    plus, minus = one_sided_costates(tr, res)["lq"]
    assert np.isnan(plus[-1]).all() and np.isnan(minus[0]).all()
    np.testing.assert_allclose(plus[1:-1], minus[1:-1], atol=1e-8)


@functools.cache
def brachistochrone_errors(method: str, grids: tuple[int, ...]) -> tuple[np.ndarray, ...]:
    """Largest knot errors (3,) of (lambda_x, lambda_y, lambda_v) against the cycloid's."""
    out = []
    for n in grids:
        tr = transcribe(P.brachistochrone(intervals=n), method=method, options=TOL)
        res = tr.solve(P.brachistochrone_guess())
        assert res.success, res.summary()
        lam = costates(tr, res)["slide"]
        out.append(np.max(np.abs(lam - P.brachistochrone_costates(res.phase("slide").t)),
                          axis=0))
    return tuple(out)


@pytest.mark.parametrize(("method", "grids", "order"),
                         [("trapezoidal", (10, 20, 40), 1.7),
                          ("hermite-simpson-separated", (10, 20), 3.5)])
def test_brachistochrone_costates_converge_to_the_cycloids(method: str, grids: tuple[int, ...],
                                                           order: float) -> None:
    # Free final time, Mayer cost, a control on its bound at the start (theta(0) = pi/2,
    # v(0) = 0). Hermite-Simpson's lambda_v stalls at about 1e-8 from 40 intervals on, at the
    # first knot: IPOPT's tolerance there (1e-14 brings it to 6e-10), hence two grids.
    errors = brachistochrone_errors(method, grids)
    for a, b in zip(errors[:-1], errors[1:], strict=True):
        assert np.all(np.log2(a / b) > order), errors


def test_brachistochrone_costates_satisfy_the_free_time_conditions() -> None:
    # Independent of the closed form: H = -1 along the optimum (free tf, Mayer tf),
    # lambda_x and lambda_y constant (x, y do not enter f), H_theta = 0 inside the bounds.
    tr = transcribe(P.brachistochrone(intervals=40), method="hermite-simpson", options=TOL)
    res = tr.solve(P.brachistochrone_guess())
    assert res.success, res.summary()
    ph = res.phase("slide")
    lam = costates(tr, res)["slide"]
    H = np.sum(lam * ph.xdot, axis=1)
    np.testing.assert_allclose(H, -1.0, atol=1e-6)
    np.testing.assert_allclose(lam[:, :2], lam[:1, :2].repeat(lam.shape[0], 0), atol=1e-6)
    th, v = ph.u[:, 0], ph.x[:, 2]
    h_theta = v * (-lam[:, 0] * np.sin(th) + lam[:, 1] * np.cos(th)) + lam[:, 2] * 9.81 * \
        np.cos(th)
    np.testing.assert_allclose(h_theta[1:], 0.0, atol=1e-4)


def test_every_phase_of_a_multiphase_problem() -> None:
    tr = transcribe(P.two_phase_jump(), method="hermite-simpson-separated")
    res = tr.solve()
    lam = costates(tr, res)
    assert set(lam) == {"before", "after"}
    assert all(v.shape == (7, 2) and np.all(np.isfinite(v)) for v in lam.values())


def test_a_result_of_another_transcription_is_refused() -> None:
    res = transcribe(P.smooth_lq(8), method="trapezoidal").solve()
    with pytest.raises(ProblemError, match="costates"):
        costates(transcribe(P.smooth_lq(8), method="hermite-simpson"), res)
    with pytest.raises(ProblemError, match="costates"):
        costates(transcribe(P.smooth_lq(10), method="trapezoidal"), res)


@pytest.mark.parametrize("method", METHODS)
def test_costates_do_not_depend_on_the_nlp_scaling(method: str) -> None:
    # Result keeps unscaled multipliers: the same costates with or without the NLP's scaling
    # (state and defect scales 5, objective scale 7) as with none.
    def solved(scaled: bool) -> dict[str, np.ndarray]:
        problem = P.free_end_lq(intervals=12)
        if scaled:
            ph = dataclasses.replace(problem.phases[0], state_scales={"x": 5.0},
                                     control_scales={"u": 3.0})
            problem = dataclasses.replace(problem, phases=[ph], objective_scale=7.0)
        tr = transcribe(problem, method=method, options=TOL, scaling=scaled)
        return costates(tr, tr.solve())
    np.testing.assert_allclose(solved(True)["lq"], solved(False)["lq"], atol=1e-8)


def test_a_ratio_cost_scales_the_costates_by_its_denominator() -> None:
    # J = (int L dt) / D with D = 2 + 0 * x(T) (an expression of the ends): lambda of J is
    # lambda of int L dt divided by D, since the optimum does not move.
    problem = P.free_end_lq(intervals=12)
    ratio = dataclasses.replace(
        problem, cost_denominator=lambda ends, p: 2.0 + 0.0 * ends["lq"].xf[0])
    plain_tr = transcribe(problem, options=TOL)
    ratio_tr = transcribe(ratio, options=TOL)
    plain = costates(plain_tr, plain_tr.solve())["lq"]
    np.testing.assert_allclose(costates(ratio_tr, ratio_tr.solve())["lq"], plain / 2.0,
                               atol=1e-8)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("kind", ["path", "bound"])
def test_the_jump_at_a_knot_is_its_active_rows_multiplier(method: str, kind: str) -> None:
    # With v <= 1.2 active over the middle of the move (a path row at knots and midpoints, or
    # a box bound), stationarity in x_k reads lambda_k^+ - lambda_k^- = -(c_x^T pi_k + lam_x):
    # the one-sided costates jump by the multiplier of the knot's own rows, exactly (the
    # midpoint rows enter the interval terms, not the jump).
    problem = P.with_path_constraint(20) if kind == "path" else P.with_state_bound(20)
    tr = transcribe(problem, method=method, options=TOL)
    res = tr.solve()
    assert res.success, res.summary()
    plus, minus = one_sided_costates(tr, res)["move"]
    pl = tr.layout.phase("move")
    if kind == "path":
        rows = tr.path_rows("move", "speed")[:pl.knots]  # the knot rows come first
        knot_multiplier = res.lam_g[rows]
    else:
        knot_multiplier = res.lam_x[pl.across_knots("state", "v")]
    assert np.sum(np.abs(knot_multiplier[1:-1]) > 1e-3) >= 5  # active at several knots
    jump = (plus - minus)[1:-1]
    scale = np.max(np.abs(plus[:-1]))
    np.testing.assert_allclose(jump[:, 0], 0.0, atol=1e-9 * scale)
    np.testing.assert_allclose(jump[:, 1], -knot_multiplier[1:-1], atol=1e-9 * scale)
