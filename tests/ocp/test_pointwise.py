"""Derivatives assembled from point functions (``compiled="points"``, gaitopt.ocp.pointwise):
the same values as CasADi's derivatives of the expanded NLP (compiled and in the VM), the
same optima, and the disk cache of the compiled point libraries (reused; rebuilt when the
model changes)."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import casadi as ca
import numpy as np
import problems as P
import pytest

from gaitopt import codegen
from gaitopt.ocp import (
    Duration,
    Parameter,
    PathConstraint,
    Phase,
    Problem,
    ProblemError,
    Transcription,
    transcribe,
)
from gaitopt.ocp.guess import warm_start_of
from gaitopt.ocp.solver import EVAL_KINDS

SEPARATED = "hermite-simpson-separated"


def nonlinear(gain: float = 1.0, intervals: int = 5, rate: float = 0.0) -> Problem:
    """A pendulum-like phase whose dynamics, path constraint and integrand depend nonlinearly
    on the states, controls, time and parameters, with a duration that is a nonlinear
    expression of a free parameter (so the knot times are nonlinear in w): every term of the
    chain rule (outer, cross, point and time Hessians) is nonzero. ``rate``: the weight of a
    control-rate term (``r int tau'^2 dt``, with 1 / h of the duration expression)."""
    def f(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        return ca.vertcat(x[1] * p[0], -gain * ca.sin(x[0]) * p[1] + u[0] * ca.cos(t * x[0]))

    duration = Duration.of_parameters(lambda p: 0.5 + p[0] ** 2)
    swing = Phase("swing", ["q", "w"], ["tau"], f, duration,
                  initial_state={"q": 0.0, "w": 0.0}, final_state={"q": 1.0},
                  lagrange=lambda x, u, p, t: u[0] ** 2 * (1 + x[1] ** 2) + p[0] * t,
                  path_constraints=[PathConstraint("reach", lambda x, u, p, t:
                                                   x[0] * x[1] + ca.exp(0.1 * u[0] * t),
                                                   lower=-5.0, upper=5.0)],
                  intervals=intervals,
                  control_rate_weights={"tau": rate} if rate else {})
    return Problem([swing], parameters=[Parameter("a", 0.5, 2.0, guess=1.0),
                                        Parameter("b", 1.0, 1.0)])


def solver_values(tr: Transcription, w: np.ndarray, lam: np.ndarray
                  ) -> dict[str, list[np.ndarray]]:
    """Every solver function of ``tr`` at scaled ``w`` (dense outputs)."""
    solver = tr.solver(tr.options)
    out = {}
    for kind in EVAL_KINDS:
        fn = solver.get_function(kind)
        args = [w, []] + ([0.7, lam] if kind == "nlp_hess_l" else [])
        res = fn(*args)
        res = res if isinstance(res, list | tuple) else [res]
        out[kind] = [np.asarray(ca.DM(r).full()) for r in res]
    return out


@pytest.mark.parametrize("make", [nonlinear, lambda: P.periodic_ratio(intervals=4),
                                  lambda: P.brachistochrone(intervals=6),
                                  lambda: nonlinear(rate=0.3)],
                         ids=["nonlinear", "periodic_ratio", "brachistochrone", "control_rate"])
@pytest.mark.parametrize("compiled_points", [True, False], ids=["compiled", "vm"])
def test_point_derivatives_equal_those_of_the_expanded_nlp(
        make: object, compiled_points: bool, tmp_path: Path,
        monkeypatch: pytest.MonkeyPatch) -> None:
    from gaitopt.ocp import pointwise

    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    monkeypatch.setattr(pointwise, "TEMPLATE_MIN_INTERVALS", 0)  # the interval templates too
    if not compiled_points:
        monkeypatch.setattr(codegen, "has_compiler", lambda: False)
    problem = make()  # type: ignore[operator]
    ref = transcribe(problem, method=SEPARATED)
    tr = transcribe(problem, method=SEPARATED, compiled="points")
    assert tr._pointwise is not None and tr._pointwise.compiled == compiled_points
    rng = np.random.default_rng(3)
    w = ref.initial_guess() / ref.nlp.d_w * (1 + 0.1 * rng.standard_normal(ref.layout.size))
    w += 0.05 * rng.standard_normal(w.size)
    lam = rng.standard_normal(ref.nlp.lbg.size)
    expected, got = solver_values(ref, w, lam), solver_values(tr, w, lam)
    for kind in EVAL_KINDS:
        for e, g in zip(expected[kind], got[kind], strict=True):
            assert g.shape == e.shape, kind
            assert np.max(np.abs(g - e)) <= 1e-11 * max(1.0, np.max(np.abs(e))), kind
    # The Hessian is not trivially zero anywhere it matters (the test could fail).
    assert np.count_nonzero(expected["nlp_hess_l"][0]) > ref.layout.size


def test_points_mode_reaches_the_same_optimum(tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    plain = transcribe(P.periodic_ratio(intervals=6), method=SEPARATED).solve()
    res = transcribe(P.periodic_ratio(intervals=6), method=SEPARATED,
                     compiled="points").solve()
    assert res.success and plain.success
    assert res.objective == pytest.approx(4.0, rel=1e-6)       # J* = 2 sqrt(c), c = 4
    # The same NLP evaluated by compiled point functions: the same optimum within 10 x the
    # solver's accuracy (ipopt.tol 1e-8); iteration counts may differ in the last bits.
    assert res.objective == pytest.approx(plain.objective, rel=1e-7)
    assert np.allclose(res.w, plain.w, rtol=1e-6, atol=1e-7)


def test_a_result_reports_through_the_compiled_point_functions(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The result of ``compiled="points"`` evaluates its knot dynamics, path values and
    interval error estimates through the compiled libraries (not CasADi's VM), and they equal
    the VM's at the same NLP point to rounding."""
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    problem = nonlinear(1.3, intervals=6)
    vm = transcribe(problem, method=SEPARATED)
    tr = transcribe(problem, method=SEPARATED, compiled="points")
    assert tr._pointwise is not None and tr._pointwise.compiled
    pf = tr.phase_functions[0]
    evaluator = tr._pointwise.evaluator(pf.point)
    assert evaluator is not pf.point and evaluator.is_a("MXFunction")
    assert tr._pointwise.evaluator(vm.phase_functions[0].point) is vm.phase_functions[0].point
    start = warm_start_of(vm.solve())
    asked: list[ca.Function] = []
    original = type(tr._pointwise).evaluator

    def spy(self: object, point: ca.Function) -> ca.Function:
        asked.append(point)
        return original(self, point)  # type: ignore[arg-type]

    monkeypatch.setattr(type(tr._pointwise), "evaluator", spy)
    a, b = vm.result_at(start), tr.result_at(start)
    assert asked == [pf.point for pf in tr.phase_functions]  # the result used them
    for pa, pb in zip(a.phases, b.phases, strict=True):
        np.testing.assert_allclose(pb.xdot, pa.xdot, rtol=1e-12, atol=1e-12)
        for name in pa.path:
            np.testing.assert_allclose(pb.path[name], pa.path[name], rtol=1e-12, atol=1e-12)
        assert np.all(pa.error > 0)  # the estimate is not trivially zero
        np.testing.assert_allclose(pb.error, pa.error, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(pb.error_by_state, pa.error_by_state, rtol=1e-9, atol=1e-15)


def test_point_libraries_are_cached_and_rebuilt_when_the_model_changes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    first = transcribe(nonlinear(1.0), method=SEPARATED, compiled="points")
    libs = sorted(tmp_path.glob("pt_*.so"))
    # One library for the phase's point function, one for the ends function's rows.
    assert [lib.name.split("-")[0] for lib in libs] == ["pt_ends_rows", "pt_point_swing"]
    inodes = [lib.stat().st_ino for lib in libs]  # a rebuilt library gets a new inode

    def no_compiling(*args: object, **kwargs: object) -> None:
        raise AssertionError("compiled although the library is cached")

    # Another mesh and another process-level build: the library is loaded, not compiled.
    monkeypatch.setattr(codegen, "compile_libraries", no_compiling)
    again = transcribe(nonlinear(1.0, intervals=9), method=SEPARATED, compiled="points")
    assert sorted(tmp_path.glob("pt_*.so")) == libs
    assert [lib.stat().st_ino for lib in libs] == inodes
    assert again.solve().success
    monkeypatch.undo()
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    # A changed model (another gain in the dynamics) compiles a new point library; the
    # ends are unchanged, so their library is reused.
    changed = transcribe(nonlinear(2.0), method=SEPARATED, compiled="points")
    assert len(list(tmp_path.glob("pt_*.so"))) == 3
    assert [lib.stat().st_ino for lib in libs] == inodes
    a, b = first.solve(), changed.solve()
    assert a.success and b.success and not math.isclose(a.objective, b.objective)


def test_compiling_is_logged_and_a_cached_library_is_not(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """A first build says that it compiles (the wait of a machine's first solve) and how long
    it took; a build from the cache says nothing."""
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    with caplog.at_level(logging.INFO, logger="gaitopt"):
        transcribe(nonlinear(1.7), method=SEPARATED, compiled="points", build_solver=False)
    said = [r.getMessage() for r in caplog.records if r.name == "gaitopt.ocp.pointwise"]
    assert len(said) == 2 and said[0].startswith("compiling 2 point libraries")
    assert str(tmp_path) in said[0] and said[1].startswith("compiled in ")
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="gaitopt"):
        transcribe(nonlinear(1.7, intervals=7), method=SEPARATED, compiled="points",
                   build_solver=False)
    assert not [r for r in caplog.records if r.name == "gaitopt.ocp.pointwise"]


def test_points_mode_refuses_the_compressed_form() -> None:
    with pytest.raises(ProblemError, match="compiled='points' needs a method"):
        transcribe(P.double_integrator(4), compiled="points")


@pytest.mark.slow
def test_walking_optimum_of_the_points_mode_is_optimal_for_the_expanded_nlp() -> None:
    # The walking solve evaluates the separated form by points; from its optimum, the same
    # NLP evaluated by CasADi's derivatives of the expanded graph converges to the same point.
    from gaitopt.gait.formulations.select import problem_for, stage_bounds
    from gaitopt.gait.formulations.step_parameters import (
        Relaxation,
        parameter_bounds,
        with_step_time,
    )
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.gait.solve.staged import solve_walking
    from gaitopt.gait.solve.transcriptions import transcription_for
    from gaitopt.robot import load_model

    model = load_model("five-link")
    options = GaitOptions.paper(speed=0.2, transcription=SEPARATED)
    solution = solve_walking(model, options)
    assert solution.success
    tr = transcription_for(model, options, options.knots)
    assert tr.compiled == "points"
    problem = problem_for(model, options)
    vm = transcribe(problem, method=SEPARATED, options=tr.options, intervals={
        ph.name: k - 1 for ph, k in zip(problem.phases, options.knots, strict=True)})
    bounds = with_step_time(stage_bounds(vm, Relaxation(), options), options)
    again = vm.solve(solution.result, bounds=bounds, parameters=parameter_bounds(options),
                     warm_start_multipliers=True)
    assert again.success
    assert again.objective == pytest.approx(solution.result.objective, rel=1e-9)
    assert again.parameters["step_length"] == pytest.approx(
        solution.result.parameters["step_length"], rel=1e-6)


def test_a_failing_compiler_falls_back_to_the_vm(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("CC", str(tmp_path / "broken-cc"))
    (tmp_path / "broken-cc").write_text("#!/bin/sh\necho 'cc: internal error' >&2\nexit 1\n")
    (tmp_path / "broken-cc").chmod(0o755)
    with pytest.warns(RuntimeWarning, match="compiling the point functions failed"):
        tr = transcribe(P.periodic_ratio(intervals=3), method=SEPARATED, compiled="points")
    assert tr._pointwise is not None and not tr._pointwise.compiled
    assert tr.solve().objective == pytest.approx(4.0, rel=1e-6)
    assert not list(tmp_path.glob("pt_*.so"))


def test_large_point_functions_compile_split_with_the_fast_flags() -> None:
    from gaitopt.ocp.pointwise import (
        LARGE_POINT,
        LARGE_POINT_FLAGS,
        POINT_FLAGS,
        point_flags,
        point_source,
    )

    x, u, p, t = (ca.SX.sym(n) for n in "xupt")
    args = [x, u, p, t]
    small = ca.Function("small", args, [ca.sin(x) * u, p, t])
    big_expr = x
    for k in range(LARGE_POINT):
        big_expr = ca.sin(big_expr + k * u)
    big = ca.Function("big", args, [big_expr, p * x, t])
    assert small.n_instructions() <= LARGE_POINT < big.n_instructions()
    assert point_flags(small) == POINT_FLAGS and "-O1" in POINT_FLAGS
    assert point_flags(big) == LARGE_POINT_FLAGS and "-Og" in LARGE_POINT_FLAGS
    # a large point's C is split into chunk functions, a small one's is not
    assert "_chunk" in point_source(big, "pt_big", LARGE_POINT_FLAGS)
    assert "_chunk" not in point_source(small, "pt_small", POINT_FLAGS)


def _functions_values(nlp: object, w: np.ndarray, lam: np.ndarray
                      ) -> dict[str, list[ca.DM]]:
    """Every function of a :class:`~gaitopt.ocp.pointwise.PointwiseNlp` at scaled ``w``."""
    out = {}
    for kind, fn in nlp.functions.items():  # type: ignore[attr-defined]
        args = [w, []] + ([0.7, lam] if kind == "nlp_hess_l" else [])
        res = fn(*args)
        out[kind] = [ca.DM(r) for r in (res if isinstance(res, list | tuple) else [res])]
    return out


def _knot_states_problem() -> Problem:
    from test_knot_states import rest_to_rest

    return rest_to_rest(given=True, ends_read_z=True)


@pytest.mark.parametrize(("make", "method"), [
    (nonlinear, SEPARATED), (lambda: nonlinear(rate=0.3), SEPARATED),
    (lambda: P.periodic_ratio(intervals=4), SEPARATED),
    (lambda: P.two_phase_jump(intervals=3), SEPARATED), (_knot_states_problem, SEPARATED),
    # Trapezoidal (no midpoints) where it is point-wise: no path constraints at midpoints.
    (lambda: P.periodic_ratio(intervals=4), "trapezoidal"),
    (_knot_states_problem, "trapezoidal")],
    ids=["nonlinear", "control_rate", "periodic_ratio", "two_phase_jump", "knot_states",
         "trapezoidal-periodic_ratio", "trapezoidal-knot_states"])
def test_interval_templates_give_the_outer_derivatives_of_the_mesh(make: object,
                                                                   method: str) -> None:
    # The terms of the intervals from one function of an interval, derived once and mapped
    # (the default), against the same terms derived within the outer functions of this mesh:
    # the same sparsity and values at a random point (one function's derivatives summed in
    # another order: 1e-12 relative).
    problem = make()  # type: ignore[operator]
    tr = transcribe(problem, method=method, build_solver=False)
    templates = tr.pointwise_nlp(compile_c=False, interval_templates=True)
    whole = tr.pointwise_nlp(compile_c=False, interval_templates=False)
    rng = np.random.default_rng(5)
    w = tr.initial_guess() / tr.nlp.d_w * (1 + 0.1 * rng.standard_normal(tr.layout.size))
    w += 0.05 * rng.standard_normal(w.size)
    lam = rng.standard_normal(tr.nlp.lbg.size)
    got, expected = _functions_values(templates, w, lam), _functions_values(whole, w, lam)
    for kind in expected:
        for e, g in zip(expected[kind], got[kind], strict=True):
            assert g.sparsity() == e.sparsity(), kind
            e_nz, g_nz = np.array(e.nonzeros()), np.array(g.nonzeros())
            assert np.all(np.isfinite(e_nz)), kind
            assert np.max(np.abs(g_nz - e_nz), initial=0.0) <= 1e-12 * max(
                1.0, np.max(np.abs(e_nz), initial=0.0)), kind
    assert np.count_nonzero(np.array(expected["nlp_hess_l"][0].nonzeros())) > 0


def test_another_mesh_derives_no_interval_template(monkeypatch: pytest.MonkeyPatch) -> None:
    # A new mesh of a problem costs an evaluation of the derived interval functions, not a
    # derivation: the second transcription finds every template derived by the first (the
    # same function objects), and derives none.
    from gaitopt.ocp import pointwise

    monkeypatch.setattr(pointwise, "TEMPLATE_MIN_INTERVALS", 0)  # templates on small meshes

    first = transcribe(nonlinear(intervals=4), method=SEPARATED, compiled="points",
                       build_solver=False)
    before = pointwise.interval_derivations
    derived = dict(pointwise._INTERVAL_DERIVATIVES)
    second = transcribe(nonlinear(intervals=11), method=SEPARATED, compiled="points",
                        build_solver=False, functions=first.functions)
    assert pointwise.interval_derivations == before
    assert dict(pointwise._INTERVAL_DERIVATIVES) == derived
    assert second.solve().success
    # A template of another form (another duration) is derived once, then found again.
    other = Problem([Phase("swing", ["q", "w"], ["tau"],
                           lambda x, u, p, t: ca.vertcat(x[1], u[0]), 2.0,
                           initial_state={"q": 0.0, "w": 0.0}, final_state={"q": 1.0},
                           lagrange=lambda x, u, p, t: u[0] ** 2, intervals=3)])
    transcribe(other, method=SEPARATED, compiled="points", build_solver=False)
    assert pointwise.interval_derivations == before + 1
    transcribe(other, method=SEPARATED, compiled="points", build_solver=False,
               intervals=7)
    assert pointwise.interval_derivations == before + 1
    # Below the threshold the mesh's outer functions are derived: no template.
    monkeypatch.setattr(pointwise, "TEMPLATE_MIN_INTERVALS", 8)
    other = Problem([Phase("swing", ["q", "w"], ["tau"],
                           lambda x, u, p, t: ca.vertcat(x[1], u[0]), 3.0,
                           initial_state={"q": 0.0, "w": 0.0}, final_state={"q": 1.0},
                           lagrange=lambda x, u, p, t: u[0] ** 2, intervals=3)])
    transcribe(other, method=SEPARATED, compiled="points", build_solver=False)
    assert pointwise.interval_derivations == before + 1
    transcribe(other, method=SEPARATED, compiled="points", build_solver=False, intervals=8)
    assert pointwise.interval_derivations == before + 2


@pytest.mark.parametrize("selections", [True, False], ids=["selections", "general"])
def test_scatter_is_the_product_with_constant_matrices(selections: bool) -> None:
    # C1 B C2 as a constant map of B's nonzeros (repeated columns of C2: entries that add up).
    from gaitopt.ocp.pointwise import _Scatter

    rng = np.random.default_rng(2)
    block = ca.Sparsity.triplet(4, 5, [0, 1, 3, 2, 0, 3], [0, 1, 1, 3, 4, 4])
    if selections:
        C1 = ca.DM.triplet([0, 2, 1], [0, 1, 3], [2.0, -1.0, 0.5], 3, 4)
        C2 = ca.DM.triplet([0, 1, 3, 4], [2, 0, 2, 1], [1.0, 3.0, -2.0, 1.5], 5, 3)
    else:
        C1 = ca.DM(rng.standard_normal((3, 4)))
        C2 = ca.DM(rng.standard_normal((5, 3)))
    values = rng.standard_normal(block.nnz())
    scatter = _Scatter(C1, block, C2)
    got = ca.Function("f", [x := ca.MX.sym("x", block.nnz())], [scatter(x)])(values)
    expected = ca.mtimes([C1, ca.DM(block, values), C2])
    assert np.allclose(np.array(ca.densify(got)), np.array(ca.densify(expected)),
                       rtol=1e-14, atol=1e-14)


def test_selections_are_read_off_by_evaluation_and_products_are_not() -> None:
    """Rows that are a constant times one input are selections; a product of two inputs
    (whose probe ratio is an integer beyond the inputs: (2 * 3) - 1 = 5 here) and a sum are
    not, and do not break the probing."""
    from gaitopt.ocp.pointwise import _selections

    u = ca.SX.sym("u", 3)
    v = ca.vertcat(2 * u[1], u[1] * u[2], u[0] + u[2], -0.5 * u[0])
    S, rest = _selections(v, u)
    assert rest == [1, 2]
    expected = np.zeros((4, 3))
    expected[0, 1], expected[3, 0] = 2.0, -0.5
    np.testing.assert_array_equal(np.array(ca.densify(S)), expected)


def test_identity_cache_finds_the_same_objects_and_keeps_the_newest() -> None:
    from gaitopt.ocp.functions import IdentityCache

    cache = IdentityCache(2)
    made: list[int] = []

    def make(value: int) -> object:
        return lambda: made.append(value) or value

    a, b = object(), object()
    assert cache.get(("x", a), make(1)) == 1
    assert cache.get(("x", a), make(2)) == 1          # the same object: found
    assert cache.get(("y", a), make(3)) == 3          # another key
    assert cache.get(("x", b), make(4)) == 4          # another object: made (evicts x, a)
    assert cache.get(("x", a), make(5)) == 5
    assert made == [1, 3, 4, 5]
