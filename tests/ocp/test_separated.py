"""Separated Hermite-Simpson: the layout of its midpoint variables, its equivalence with the
compressed form (same optimum on every mesh), warm starts across forms, and the structure of
its exact Hessian (no dynamics nested in dynamics)."""

from __future__ import annotations

import math

import numpy as np
import problems as P
import pytest

from gaitopt.ocp import Result, transcribe
from gaitopt.ocp.bounds import describe

COMPRESSED, SEPARATED = "hermite-simpson", "hermite-simpson-separated"


def midpoints(res: Result, phase: int | str = 0) -> np.ndarray:
    ph = res.phase(phase)
    return 0.5 * (ph.t[:-1] + ph.t[1:])


def test_layout_appends_the_midpoint_states_after_the_knots_of_each_phase() -> None:
    # Two phases of 5 knots x (2 states + 1 control) and 4 midpoints x 2 states, then D, vbar.
    tr = transcribe(P.periodic_ratio(intervals=4), method=SEPARATED)
    lay = tr.layout
    first, second = lay.phase("first"), lay.phase("second")
    assert (first.start, first.midpoint_start, first.end) == (0, 15, 23)
    assert (second.start, second.midpoint_start, second.end) == (23, 38, 46)
    assert lay.parameter_start == 46 and lay.size == 48
    assert first.midpoints == 4 and first.midpoint_indices().shape == (4, 2)
    assert first.midpoint_index("v", 0) == 16 and first.midpoint_index("s", -1) == 21
    np.testing.assert_array_equal(first.midpoint_indices()[:, 1],
                                  np.arange(48)[first.across_midpoints("v")])
    # The knot accessors are those of the compressed layout, shifted by the earlier phases.
    assert first.across_knots("state", "v") == slice(1, 15, 3)
    assert lay.index("second", "control", "a", 2) == 23 + 2 * 3 + 2
    assert describe(lay, 16) == "phase 'first' state 'v' midpoint 0"
    assert describe(lay, 14) == "phase 'first' control 'a' knot 4"
    with pytest.raises(IndexError, match="midpoint 4 out of range"):
        first.midpoint_index("s", 4)
    # The compressed layout has no midpoints and is unchanged.
    plain = transcribe(P.periodic_ratio(intervals=4)).layout
    assert plain.phase("first").midpoints == 0 and plain.size == 32
    assert plain.phase("first").midpoint_indices().shape == (0, 2)
    assert plain.signature() != lay.signature()


def test_constraint_blocks_and_nlp_size_add_one_midpoint_defect_per_state_and_interval() -> None:
    sep = transcribe(P.periodic_ratio(intervals=4), method=SEPARATED)
    com = transcribe(P.periodic_ratio(intervals=4))
    blocks = [b.name for b in sep.nlp.constraints.blocks]
    i = blocks.index("first/defects")
    assert blocks[i + 1] == "first/midpoint defects"
    mid = sep.nlp.constraints.block("first/midpoint defects")
    assert mid.shape == (4, 2)
    assert mid.rows.start == sep.nlp.constraints.block("first/defects").rows.stop
    a, b = sep.nlp_size(), com.nlp_size()
    extra = 2 * 4 * 2  # phases x intervals x states
    assert a.variables == b.variables + extra
    assert a.equality_constraints == b.equality_constraints + extra
    assert a.inequality_constraints == b.inequality_constraints


def test_state_bounds_hold_at_the_midpoints_unless_midpoint_bounds_is_off() -> None:
    bounded = transcribe(P.periodic_ratio(intervals=4), method=SEPARATED)
    free = transcribe(P.periodic_ratio(intervals=4), method=SEPARATED, midpoint_bounds=False)
    com = transcribe(P.periodic_ratio(intervals=4))
    s_bound = P.periodic_ratio().phases[0].state_bounds["v"]
    for phase in ("first", "second"):
        pl = bounded.layout.phase(phase)
        v_mid, v_knots = pl.across_midpoints("v"), pl.across_knots("state", "v")
        assert np.all(bounded.bounds().lbw[v_mid] == s_bound[0])
        assert np.all(bounded.bounds().ubw[v_mid] == s_bound[1])
        assert np.all(np.isinf(free.bounds().lbw[v_mid]))
        # Initial/final knot bounds stay at the knots.
        np.testing.assert_array_equal(free.bounds().lbw[v_knots], bounded.bounds().lbw[v_knots])
    # A whole-phase bound follows the same rule; a bound at one knot touches no midpoint.
    idx = free.layout.phase("first").midpoint_indices()[:, 1]
    assert np.all(np.isinf(free.bounds().with_state("first", "v", -3.0, 3.0).lbw[idx]))
    assert np.all(bounded.bounds().with_state("first", "v", -3.0, 3.0).lbw[idx] == -3.0)
    assert np.all(bounded.bounds().with_state("first", "v", -3.0, 3.0, knot=2).lbw[idx]
                  == s_bound[0])
    assert free.nlp_size().box_bounded_variables == com.nlp_size().box_bounded_variables
    assert bounded.nlp_size().box_bounded_variables == (
        com.nlp_size().box_bounded_variables + 2 * 4)  # v bounded at 4 midpoints, 2 phases


def test_midpoint_bounds_keep_the_interpolated_state_within_its_bounds() -> None:
    """A state bound active between knots only: on 3 intervals the rest-to-rest speed
    v = 6t - 6t^2 is 4/3 at the knots and 1.5 at the middle midpoint, above the bound 1.45.
    With midpoint bounds the cubic Hermite state respects it at the midpoints; the compressed
    form (and midpoint_bounds=False) only at the knots, with a lower cost (J = 12)."""
    problem = P.with_state_bound(3, 1.45)
    com = transcribe(problem).solve()
    free = transcribe(problem, method=SEPARATED, midpoint_bounds=False).solve()
    bounded = transcribe(problem, method=SEPARATED).solve()
    assert com.success and free.success and bounded.success
    assert free.objective == pytest.approx(com.objective, rel=1e-8)
    mid = midpoints(com)
    assert com.objective == pytest.approx(12.0, rel=1e-9)
    assert com.phase(0).x_at(mid)[1, 1] == pytest.approx(1.5, abs=1e-9)
    assert bounded.phase(0).x_at(mid)[:, 1].max() == pytest.approx(1.45, abs=1e-7)
    assert bounded.phase(0).x_mid[:, 1].max() == pytest.approx(1.45, abs=1e-7)  # type: ignore[index]
    assert bounded.objective > com.objective + 1e-3


@pytest.mark.parametrize(("problem", "guess"), [
    (lambda: P.brachistochrone(intervals=6), P.brachistochrone_guess),
    (lambda: P.brachistochrone(intervals=15), P.brachistochrone_guess),
    (lambda: P.boundary_layer(intervals=10), lambda: None),
    (lambda: P.periodic_ratio(intervals=5), lambda: None),
    (lambda: P.smooth_lq(64), lambda: None),  # a fine grid of a smooth problem
])
def test_both_forms_reach_the_same_optimum_on_the_same_mesh(problem, guess) -> None:  # type: ignore[no-untyped-def]
    """Eliminating x_m by its midpoint defect gives the compressed NLP back, so the optima
    agree to the solver's tolerance on every mesh, coarse or fine: objective, knot values,
    interval error estimates."""
    com = transcribe(problem(), method=COMPRESSED).solve(guess())
    sep = transcribe(problem(), method=SEPARATED, midpoint_bounds=False).solve(guess())
    assert com.success and sep.success, (com.summary(), sep.summary())
    assert sep.objective == pytest.approx(com.objective, rel=1e-8, abs=1e-10)
    for a, b in zip(com.phases, sep.phases, strict=True):
        np.testing.assert_allclose(b.t, a.t, atol=1e-7)
        np.testing.assert_allclose(b.x, a.x, atol=1e-6)
        np.testing.assert_allclose(b.u, a.u, atol=1e-5)
        assert a.x_mid is None and b.x_mid is not None
        np.testing.assert_allclose(b.error, a.error, rtol=1e-3, atol=1e-10)
    assert set(sep.errors_by_phase()) == {ph.name for ph in sep.phases}
    assert max(sep.errors_by_phase().values()) == sep.max_error


def test_midpoint_variables_are_the_cubic_hermite_midpoints_at_the_optimum() -> None:
    res = transcribe(P.brachistochrone(intervals=12), method=SEPARATED).solve(
        P.brachistochrone_guess())
    assert res.success
    ph = res.phase("slide")
    assert ph.x_mid is not None and ph.x_mid.shape == (12, 3)
    np.testing.assert_allclose(ph.x_mid, ph.x_at(midpoints(res)), atol=1e-9)
    # The cycloid at the midpoints too (as accurate as at the knots).
    R, _, _ = P.cycloid(1.0, 0.6)
    phi = midpoints(res) * math.sqrt(P.G / R)
    np.testing.assert_allclose(ph.x_mid[:, 1], R * (1 - np.cos(phi)), atol=2e-4)


@pytest.mark.parametrize(("source", "target"), [(COMPRESSED, SEPARATED),
                                                (SEPARATED, COMPRESSED)])
def test_a_result_of_one_form_warm_starts_the_other(source: str, target: str) -> None:
    start = transcribe(P.brachistochrone(intervals=20), method=source).solve(
        P.brachistochrone_guess())
    tr = transcribe(P.brachistochrone(intervals=20), method=target)
    cold = tr.solve(P.brachistochrone_guess())
    w0 = tr.initial_guess(start)
    # The start is the source's solution: its knots, and the Hermite midpoints of its
    # interpolant for the midpoint variables, which satisfy the midpoint defects.
    pl = tr.layout.phase("slide")
    np.testing.assert_allclose(w0[pl.state_indices()], start.phase(0).x, atol=1e-12)
    if target == SEPARATED:
        np.testing.assert_allclose(w0[pl.midpoint_indices()],
                                   start.phase(0).x_at(midpoints(start)), atol=1e-12)
        g = np.asarray(tr.nlp.evaluate(w0)[0], dtype=float).ravel()
        rows = tr.nlp.constraints.block("slide/midpoint defects").rows
        assert np.max(np.abs(g[rows])) < 1e-12
    warm = tr.solve(start)
    assert warm.success and cold.success
    assert warm.objective == pytest.approx(cold.objective, rel=1e-9)
    assert warm.objective == pytest.approx(start.objective, rel=1e-8)
    assert warm.iterations < cold.iterations
    # Multipliers are only passed on the same layout; across forms the values still start it.
    again = tr.solve(start, warm_start_multipliers=True)
    assert again.success and again.objective == pytest.approx(cold.objective, rel=1e-9)


def test_warm_start_from_the_other_form_on_another_mesh() -> None:
    coarse = transcribe(P.brachistochrone(intervals=10)).solve(P.brachistochrone_guess())
    tr = transcribe(P.brachistochrone(intervals=25), method=SEPARATED)
    cold = tr.solve(P.brachistochrone_guess())
    warm = tr.solve(coarse)
    assert warm.success and warm.objective == pytest.approx(cold.objective, rel=1e-8)
    assert warm.iterations < cold.iterations
    w0 = tr.initial_guess(coarse)
    t_mid = coarse.phase(0).t0 + coarse.phase(0).duration * 0.5 * (tr.mesh[0][:-1] +
                                                                   tr.mesh[0][1:])
    np.testing.assert_allclose(w0[tr.layout.phase("slide").midpoint_indices()],
                               coarse.phase(0).x_at(t_mid), atol=1e-12)


def test_warm_start_with_multipliers_on_the_same_separated_layout() -> None:
    tr = transcribe(P.brachistochrone(intervals=20), method=SEPARATED)
    res = tr.solve(P.brachistochrone_guess())
    again = tr.solve(res, warm_start_multipliers=True)
    assert again.success and again.iterations <= 2
    assert again.objective == pytest.approx(res.objective, rel=1e-9)


def test_exact_hessian_couples_no_knot_state_with_the_next_knot() -> None:
    """Compressed: f_m is f of an expression of f_k and f_{k+1}, so the Hessian of the
    Lagrangian couples the states of knot k with the variables of knot k + 1. Separated: each
    term is f at one grid point (knot: x_k, u_k; midpoint: x_m and the controls u_k, u_{k+1}
    it interpolates), so knot states couple with no other knot."""
    coupled = {}
    for method in (COMPRESSED, SEPARATED):
        tr = transcribe(P.brachistochrone(intervals=6), method=method)
        hess = tr.solver(tr.options).get_function("nlp_hess_l")
        sp = np.array(hess.sparsity_out(0)).astype(bool)
        sp = sp | sp.T
        pl = tr.layout.phase("slide")
        S, U = pl.state_indices(), pl.control_indices()
        coupled[method] = any(sp[np.ix_(S[k], np.concatenate([S[k + 1], U[k + 1]]))].any()
                              for k in range(pl.knots - 1))
        if method == SEPARATED:
            # A midpoint state couples only with itself, the interval's controls and T.
            own = set(pl.midpoint_indices()[2]) | set(U[2]) | set(U[3]) | {pl.duration_index}
            rows = np.flatnonzero(sp[pl.midpoint_indices()[2]].any(axis=0))
            assert set(rows.tolist()) <= own
    assert coupled == {COMPRESSED: True, SEPARATED: False}


def test_path_rows_of_the_separated_form_include_the_midpoints() -> None:
    tr = transcribe(P.with_path_constraint(20, 1.2), method=SEPARATED)
    rows = tr.path_rows("move", "speed")
    assert rows.size == 21 + 20
    free = tr.solve(bounds=tr.bounds().with_rows(rows, -np.inf, np.inf))
    assert free.objective == pytest.approx(12.0, rel=1e-8)
