"""Order of accuracy, error estimates and mesh refinement."""

from __future__ import annotations

import numpy as np
import problems as P
import pytest
from scipy.integrate import solve_ivp
from scipy.stats import spearmanr

from gaitopt.ocp import transcribe
from gaitopt.ocp.refine import refine, refined_mesh


def knot_error(method: str, intervals: int) -> float:
    res = transcribe(P.smooth_lq(intervals), method=method).solve()
    assert res.success, res.summary()
    ph = res.phase(0)
    return float(np.max(np.abs(ph.x[:, 0] - P.smooth_lq_state(ph.t))))


HS_FORMS = ["hermite-simpson", "hermite-simpson-separated"]


@pytest.mark.parametrize(("method", "low", "high"),
                         [("hermite-simpson", 12.0, 20.0),
                          ("hermite-simpson-separated", 12.0, 20.0),
                          ("trapezoidal", 3.0, 5.0)])
def test_state_error_order_on_mesh_halving(method: str, low: float, high: float) -> None:
    errors = [knot_error(method, n) for n in (8, 16, 32)]
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    # Hermite-Simpson: ratio -> 2^4 = 16; trapezoidal: -> 2^2 = 4.
    assert low < ratios[-1] < high, (errors, ratios)
    assert ratios[-1] > ratios[0] * 0.95


@pytest.mark.parametrize("hs", HS_FORMS)
def test_hermite_simpson_beats_trapezoidal(hs: str) -> None:
    assert knot_error(hs, 16) < 1e-2 * knot_error("trapezoidal", 16)


def local_errors(res) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Independent reference: integrate x' = -x + u(t) (u the linear control) accurately over
    each interval from x_k and compare with x_{k+1}."""
    ph = res.phase(0)
    out = []
    for k in range(ph.t.size - 1):
        sol = solve_ivp(lambda t, x: -x + ph.u_at([t])[0], (ph.t[k], ph.t[k + 1]),
                        [ph.x[k, 0]], rtol=1e-12, atol=1e-14)
        out.append(abs(sol.y[0, -1] - ph.x[k + 1, 0]))
    return np.array(out)


@pytest.mark.parametrize("hs", HS_FORMS)
def test_error_estimate_ranks_intervals_like_the_true_local_error(hs: str) -> None:
    res = transcribe(P.boundary_layer(intervals=10), method=hs).solve()
    est = res.phase(0).error
    ref = local_errors(res)
    assert int(np.argmax(est)) == 0 == int(np.argmax(ref))
    assert spearmanr(est, ref).statistic > 0.9
    # Same order of magnitude as the reference (both integrate the residual over an interval).
    assert 0.1 < est[0] / ref[0] < 100.0


@pytest.mark.parametrize("hs", HS_FORMS)
def test_refinement_meets_tolerance_and_lowers_the_largest_error(hs: str) -> None:
    tol = 1e-7
    out = refine(P.boundary_layer(intervals=10), tol=tol, method=hs)
    assert all(r.method == hs for r in out.history)
    errors = [r.max_error for r in out.history]
    assert out.converged and out.result.max_error <= tol
    assert len(out.history) >= 2
    assert all(b < a for a, b in zip(errors, errors[1:], strict=False))
    # Only the steep start was refined: the first tenth gained the most knots.
    tau = out.result.mesh[0]
    assert np.sum(tau < 0.1) > np.sum(tau > 0.9)
    # The refined objective approaches the exact optimum J* = P(0) x0^2 from the Riccati
    # equation -P' = 2 a P + q - P^2 b^2 / r, P(1) = 0 (a = -1, b = 1, q = 1, r = eps^2).
    eps = 0.05
    ric = solve_ivp(lambda t, p: -(-2 * p + 1 - p**2 / eps**2), (1.0, 0.0), [0.0],
                    rtol=1e-12, atol=1e-14, method="Radau")
    j_star = float(ric.y[0, -1])
    assert abs(out.result.objective - j_star) < 0.05 * abs(out.history[0].objective - j_star)
    assert out.result.objective == pytest.approx(j_star, rel=1e-4)


@pytest.mark.parametrize("hs", HS_FORMS)
def test_refined_mesh_splits_only_bad_intervals(hs: str) -> None:
    res = transcribe(P.boundary_layer(intervals=10), method=hs).solve()
    err = res.phase(0).error
    tol = float(np.sort(err)[-3])  # the two largest are above tol
    new = refined_mesh(res, tol)[0]
    old = res.mesh[0]
    for k in range(old.size - 1):
        inside = np.sum((new > old[k] + 1e-12) & (new < old[k + 1] - 1e-12))
        assert (inside >= 1) == (err[k] > tol), (k, inside, err[k], tol)
    assert np.all(np.isin(np.round(old, 12), np.round(new, 12)))
