"""Multipliers mapped onto another grid of the same problem (gaitopt.ocp.regrid)."""

from __future__ import annotations

import numpy as np
import problems as P
import pytest

from gaitopt.ocp import PathConstraint, Phase, Problem, ProblemError, Result, transcribe
from gaitopt.ocp.regrid import GridPoints, map_block, mapped_multipliers, regridded
from gaitopt.ocp.transcription import Transcription

SEPARATED = "hermite-simpson-separated"
TIGHT = {"ipopt.tol": 1e-12}


def bounded_acceleration(intervals: int = 10, limit: float = 4.2) -> Problem:
    """The rest-to-rest double integrator with the path constraint ``|a| <= limit``: the
    unconstrained optimum a = 6 - 12 t exceeds 4.2 in magnitude for t < 0.15 and t > 0.85
    (4 is the least feasible limit), so the constraint is active on an arc at each end, where
    its multiplier is a density."""
    ph = Phase("move", ["s", "v"], ["a"], P.double_integrator_dynamics, 1.0,
               initial_state={"s": 0.0, "v": 0.0}, final_state={"s": 1.0, "v": 0.0},
               lagrange=P.energy, intervals=intervals,
               path_constraints=[PathConstraint("accel", lambda x, u, p, t: u[0],
                                                lower=-limit, upper=limit)])
    return Problem([ph])


def solved(problem: Problem, method: str, intervals: object) -> tuple[Transcription, Result]:
    tr = transcribe(problem, method=method, intervals=intervals, options=TIGHT)  # type: ignore[arg-type]
    res = tr.solve(P.brachistochrone_guess() if problem.phases[0].name == "slide" else None)
    assert res.success, res.summary()
    return tr, res


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.mark.parametrize("method", ["hermite-simpson", SEPARATED, "trapezoidal"])
@pytest.mark.parametrize("make", [P.with_path_constraint, P.periodic_ratio, P.two_phase_jump,
                                  P.brachistochrone])
def test_mapping_onto_the_same_grid_returns_the_multipliers(make, method) -> None:  # type: ignore[no-untyped-def]
    cosine = 0.5 * (1.0 - np.cos(np.pi * np.linspace(0.0, 1.0, 9)))
    tr, res = solved(make(), method, cosine)
    assert np.any(res.lam_g != 0.0) and np.any(res.lam_x != 0.0)
    lam_x, lam_g = mapped_multipliers(tr, res)
    np.testing.assert_allclose(lam_x, res.lam_x, rtol=1e-12, atol=1e-12 * np.abs(res.lam_x).max())
    np.testing.assert_allclose(lam_g, res.lam_g, rtol=1e-12, atol=1e-12 * np.abs(res.lam_g).max())


def test_map_block_scales_densities_by_the_new_weights() -> None:
    # A constant density 3 on knots: the multipliers are 3 * weight on either grid.
    old, new = GridPoints.of(np.linspace(0, 1, 5), "knots"), GridPoints.of(
        np.linspace(0, 1, 9) ** 2, "knots")
    np.testing.assert_allclose(map_block(3.0 * old.weight[:, None], old, new, True, True)[:, 0],
                               3.0 * new.weight)
    # A boundary part at the first knot is kept on top of the density part.
    values = 3.0 * old.weight[:, None]
    values[0] += 7.0
    out = map_block(values, old, new, True, True)[:, 0]
    assert out[0] == pytest.approx(7.0 + 3.0 * new.weight[0])
    # Values (a costate) are interpolated linearly, unscaled.
    mids_old = GridPoints.of(np.linspace(0, 1, 5), "intervals")
    mids_new = GridPoints.of(np.linspace(0, 1, 12), "intervals")
    lin = (2.0 + mids_old.tau)[:, None]
    np.testing.assert_allclose(map_block(lin, mids_old, mids_new, False)[1:-1, 0],
                               2.0 + mids_new.tau[1:-1])


@pytest.mark.parametrize(("make", "blocks"), [
    (P.smooth_lq, ["lq/defects", "lq/midpoint defects"]),
    (P.brachistochrone, ["slide/defects", "slide/midpoint defects"]),
    (bounded_acceleration, ["move/defects", "move/midpoint defects"]),
])
def test_mapped_coarse_multipliers_approximate_the_fine_optimum(make, blocks) -> None:  # type: ignore[no-untyped-def]
    """The KKT scaling: a converged coarse solution's multipliers mapped onto a grid 2.3x finer
    are within a few per cent of the fine optimum's, block by block. The midpoint defects'
    are O(h): mapped by value (no weights) they would be off by the ratio of the interval
    lengths."""
    _, coarse = solved(make(), SEPARATED, 10)
    tr, fine = solved(make(), SEPARATED, 23)
    _, lam_g = mapped_multipliers(tr, coarse)
    for name in blocks:
        rows = tr.nlp.constraints.block(name).rows
        assert rel(lam_g[rows], fine.lam_g[rows]) < 0.06, name
        if name.endswith("midpoint defects"):
            assert rel(lam_g[rows] * 23 / 10, fine.lam_g[rows]) > 0.5, name


@pytest.mark.parametrize("method", ["hermite-simpson", SEPARATED])
def test_mapped_path_multipliers_keep_their_total(method: str) -> None:
    """Path multipliers are densities times weights: mapped 10 -> 23 intervals, the total of
    the knot and midpoint rows stays within 10 % of the fine optimum's (by value it would be
    2.3x), and each block within 35 % row by row (the density has a kink at the arcs' ends
    and the discrete multipliers alternate between knots and midpoints near them)."""
    _, coarse = solved(bounded_acceleration(), method, 10)
    tr, fine = solved(bounded_acceleration(), method, 23)
    _, lam_g = mapped_multipliers(tr, coarse)
    rows = [tr.nlp.constraints.block(f"move/{b}").rows for b in ("path@knots", "path@midpoints")]
    total = sum(np.abs(lam_g[r]).sum() for r in rows)
    assert total == pytest.approx(sum(np.abs(fine.lam_g[r]).sum() for r in rows), rel=0.1)
    for r in rows:
        assert rel(lam_g[r], fine.lam_g[r]) < 0.35


def test_refinement_warm_started_with_mapped_multipliers_reaches_the_same_optimum() -> None:
    for make in (bounded_acceleration, P.with_path_constraint, P.brachistochrone):
        _, coarse = solved(make(), SEPARATED, 10)
        tr = transcribe(make(), method=SEPARATED, intervals=23, options=TIGHT)
        values = tr.solve(coarse)
        mapped = tr.solve(coarse, warm_start_multipliers=True, regrid=True)
        assert values.success and mapped.success
        assert mapped.objective == pytest.approx(values.objective, rel=1e-9)
        np.testing.assert_allclose(mapped.w, values.w, atol=1e-6)
        # The option is regridded() passed as a warm start.
        start = regridded(tr, coarse)
        again = tr.solve(start, warm_start_multipliers=True)
        assert again.success
        assert again.objective == pytest.approx(mapped.objective, rel=1e-9)
        np.testing.assert_allclose(again.w, mapped.w, atol=1e-6)
        # regridded is a pure function of (transcription, result): the same start each time.
        twice = regridded(tr, coarse)
        for name in ("w", "lam_x", "lam_g"):
            np.testing.assert_array_equal(getattr(twice, name), getattr(start, name))


def test_a_result_of_another_problem_or_method_is_refused() -> None:
    _, other = solved(P.smooth_lq(), SEPARATED, 10)
    tr = transcribe(P.with_path_constraint(), method=SEPARATED, intervals=12)
    with pytest.raises(ProblemError, match="regrid: the result is of another problem"):
        mapped_multipliers(tr, other)
    with pytest.raises(ProblemError, match="another problem"):
        tr.solve(other, warm_start_multipliers=True, regrid=True)
    # Same variables, another constraint: the rows do not add up.
    _, plain = solved(P.double_integrator(), SEPARATED, 10)
    with pytest.raises(ProblemError, match="constraint multipliers"):
        regridded(tr, plain)
    _, compressed = solved(P.with_path_constraint(), "hermite-simpson", 10)
    with pytest.raises(ProblemError, match="method 'hermite-simpson'"):
        regridded(tr, compressed)
    # Without regrid a Result of another grid is a guess of values, as before.
    assert tr.solve(compressed, warm_start_multipliers=True).success
