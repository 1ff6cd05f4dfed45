"""States given by the others at the knots (``Phase.knot_states``, :class:`KnotStates`): the
same optimum as the problem that states the equalities they solve, exact derivatives in the
point-wise mode, the result filled with their values, and clear errors."""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from gaitopt.ocp import (
    BoundaryConstraint,
    KnotStates,
    PathConstraint,
    Phase,
    Problem,
    ProblemError,
    Transcription,
    transcribe,
)
from gaitopt.ocp.solver import EVAL_KINDS

SEPARATED = "hermite-simpson-separated"


def _dynamics(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
    """``s' = v, v' = a, z' = 2 s v + gamma``: ``z = s^2`` holds along exact solutions, and
    the projection control ``gamma`` absorbs the collocation error at the knots."""
    return ca.vertcat(x[1], u[0], 2 * x[0] * x[1] + u[1])


def rest_to_rest(given: bool, ends_read_z: bool = False) -> Problem:
    """Move ``s`` from 0 to 1 at rest in 1 s minimising ``int a^2`` (optimum 12, exact for
    Hermite-Simpson: ``a = 6 - 12 t``), with ``z = s^2`` at every knot after the first:
    given by :class:`KnotStates` (``given``) or stated as an equality path constraint.
    ``ends_read_z`` adds a boundary constraint and a Mayer term on the final ``z`` (another
    problem: for derivatives only, so that the ends function reads a given state)."""
    common = dict(initial_state={"s": 0.0, "v": 0.0, "z": 0.0},
                  final_state={"s": 1.0, "v": 0.0},
                  state_bounds={"z": (-5.0, 5.0)},
                  control_bounds={"gamma": (-10.0, 10.0)}, initial_control={"gamma": 0.0},
                  lagrange=lambda x, u, p, t: u[0] ** 2, intervals=6)
    if given:
        phase = Phase("move", ["s", "v", "z"], ["a", "gamma"], _dynamics, 1.0,
                      knot_states=KnotStates(("z",), lambda x, p: x[0] ** 2), **common)
    else:
        phase = Phase("move", ["s", "v", "z"], ["a", "gamma"], _dynamics, 1.0,
                      path_constraints=[PathConstraint("z = s^2", lambda x, u, p, t:
                                                       x[2] - x[0] ** 2, 0.0, 0.0, at="knots")],
                      **common)
    if not ends_read_z:
        return Problem([phase])
    return Problem([phase], boundary_constraints=[BoundaryConstraint(
        "final z", lambda e, p: e["move"].xf[2] * e["move"].xf[0], -10.0, 10.0)],
        mayer=lambda e, p: 0.1 * e["move"].xf[2] ** 2)


def _solve(tr: Transcription) -> object:
    bounds = tr.bounds()
    rows = tr.path_rows("move", "z = s^2") if not tr.nlp.dependent.size else np.zeros(0, int)
    if rows.size:  # the first knot's row repeats the initial state
        bounds = bounds.with_rows(rows[:1], -np.inf, np.inf)
    return tr.solve(bounds=bounds)


@pytest.mark.parametrize("compiled", [None, "points"])
def test_given_states_reach_the_optimum_of_the_stated_equalities(
        compiled: str | None, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    stated = transcribe(rest_to_rest(False), method=SEPARATED, compiled=compiled)
    given = transcribe(rest_to_rest(True), method=SEPARATED, compiled=compiled)
    a, b = _solve(stated), _solve(given)
    assert a.success and b.success  # type: ignore[attr-defined]
    assert b.objective == pytest.approx(12.0, rel=1e-8)  # type: ignore[attr-defined]
    assert b.objective == pytest.approx(a.objective, rel=1e-10)  # type: ignore[attr-defined]
    # The same knot values, the given ones filled in from s.
    assert np.allclose(b.w, a.w, rtol=1e-7, atol=1e-9)  # type: ignore[attr-defined]
    x = b.phases[0].x  # type: ignore[attr-defined]
    assert np.allclose(x[1:, 2], x[1:, 0] ** 2, atol=1e-14)
    # Fewer rows: the equalities are gone (6 knots after the first).
    assert stated.nlp.lbg.size - given.nlp.lbg.size == 7
    assert given.nlp.dependent.size == 6


@pytest.mark.parametrize("method", [SEPARATED, "trapezoidal"])
def test_point_derivatives_with_given_states_equal_those_of_the_expanded_nlp(
        method: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The point-wise NLP computes the given states inside the knots' point function and
    the ends function (``fold_knot_states``): the same functions as the expanded NLP, which
    computes them in the expressions around the point functions."""
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    problem = rest_to_rest(True, ends_read_z=True)
    ref = transcribe(problem, method=method)
    tr = transcribe(problem, method=method, compiled="points")
    # The knots after the first have their own point function, which returns the given
    # states; the ends function computes the final one.
    assert tr._pointwise is not None
    names = {fn.name() for fn in tr._pointwise.point_functions}
    assert names == {"point_move", "knot_point_move", "ends_knot_states_rows"}
    rng = np.random.default_rng(5)
    w = rng.standard_normal(ref.layout.size)
    lam = rng.standard_normal(ref.nlp.lbg.size)
    for kind in EVAL_KINDS:
        args = [w, []] + ([0.7, lam] if kind == "nlp_hess_l" else [])
        expected = ref.solver(ref.options).get_function(kind)(*args)
        got = tr.solver(tr.options).get_function(kind)(*args)
        expected = expected if isinstance(expected, list | tuple) else [expected]
        got = got if isinstance(got, list | tuple) else [got]
        for e, g in zip(expected, got, strict=True):
            e, g = np.asarray(ca.DM(e).full()), np.asarray(ca.DM(g).full())
            assert np.max(np.abs(g - e)) <= 1e-11 * max(1.0, np.max(np.abs(e))), kind
    # s^2 enters the Hessian through the given z (in the knots' point Hessians).
    hess = np.asarray(ca.DM(ref.solver(ref.options).get_function("nlp_hess_l")(
        w, [], 0.7, lam)).full())
    s_knot = ref.layout.phase("move").index("state", "s", 2)
    assert abs(hess[s_knot, s_knot]) > 0.0


def test_given_states_must_not_read_themselves() -> None:
    phase = Phase("move", ["s", "v", "z"], ["a", "gamma"], _dynamics, 1.0,
                  knot_states=KnotStates(("z",), lambda x, p: x[2] + x[0]))
    with pytest.raises(ProblemError, match=r"knot_states: the values of \['z'\] must not "
                                           r"depend on those states"):
        transcribe(Problem([phase]), method=SEPARATED)
    phase = Phase("move", ["s", "v", "z"], ["a", "gamma"], _dynamics, 1.0,
                  knot_states=KnotStates(("w",), lambda x, p: x[0]))
    with pytest.raises(ProblemError, match=r"names must be distinct states of the phase"):
        transcribe(Problem([phase]), method=SEPARATED)
