"""Re-solving one transcription with other bounds and guesses, warm starts, compiled modes."""

from __future__ import annotations

import numpy as np
import problems as P
import pytest

from gaitopt.ocp import Guess, PhaseGuess, transcribe
from gaitopt.ocp.solver import merge_options
from gaitopt.ocp.transcription import WARM_START_OPTIONS


def test_resolve_with_changed_parameter_bounds_does_not_rebuild() -> None:
    tr = transcribe(P.periodic_ratio(c=4.0))
    assert tr.builds == {"nlp": 1, "solver": 1}
    free = tr.solve()
    assert free.objective == pytest.approx(4.0, rel=1e-8)
    # J(vbar) = vbar + c / vbar for a fixed mean speed (see problems.periodic_ratio).
    for vbar in (1.0, 3.0, 0.5):
        fixed = tr.solve(free, parameters={"vbar": vbar})
        assert fixed.success, fixed.summary()
        assert fixed.parameters["vbar"] == vbar
        assert fixed.objective == pytest.approx(vbar + 4.0 / vbar, rel=1e-8)
    # The same through a Bounds object.
    b = tr.bounds().with_parameter("vbar", 1.0, 1.5)
    ranged = tr.solve(bounds=b)
    assert ranged.parameters["vbar"] == pytest.approx(1.5, rel=1e-6)
    assert tr.builds == {"nlp": 1, "solver": 1}
    # Statement bounds are untouched by the overrides.
    assert tr.bounds().ubw[tr.layout.parameter("vbar")] == 10.0


def test_state_and_constraint_bound_overrides() -> None:
    tr = transcribe(P.double_integrator(6))
    b = tr.bounds().with_state("move", "s", 2.0, knot=-1)
    res = tr.solve(bounds=b)
    assert res.objective == pytest.approx(48.0, rel=1e-9)  # J = 12 d^2 for distance d
    tr2 = transcribe(P.periodic_ratio(c=4.0))
    res2 = tr2.solve(bounds=tr2.bounds().with_parameter("D", 2.0).with_parameter("vbar", 2.0))
    assert res2.objective == pytest.approx(4.0, rel=1e-8)
    assert tr2.builds["nlp"] == 1


def test_warm_start_from_a_result_on_another_mesh() -> None:
    coarse = transcribe(P.brachistochrone(intervals=10)).solve(P.brachistochrone_guess())
    tr = transcribe(P.brachistochrone(intervals=25))
    cold = tr.solve(P.brachistochrone_guess())
    warm = tr.solve(coarse)
    assert cold.success and warm.success
    assert warm.objective == pytest.approx(cold.objective, rel=1e-8)
    assert warm.iterations < cold.iterations
    # The initial guess is the coarse result's interpolant at the new knots.
    w0 = tr.initial_guess(coarse)
    pl = tr.layout.phase("slide")
    t_new = coarse.phase(0).t0 + coarse.phase(0).duration * tr.mesh[0]
    np.testing.assert_allclose(w0[pl.state_indices()], coarse.phase(0).x_at(t_new))
    assert w0[pl.duration_index] == pytest.approx(coarse.phase(0).duration)


def test_warm_start_multipliers_on_the_same_mesh() -> None:
    tr = transcribe(P.brachistochrone(intervals=20))
    res = tr.solve(P.brachistochrone_guess())
    again = tr.solve(res, warm_start_multipliers=True)
    assert again.success and again.iterations <= 2
    assert again.objective == pytest.approx(res.objective, rel=1e-9)
    assert tr.builds["nlp"] == 1


def test_warm_start_options_override_its_defaults_which_override_options(
        monkeypatch: pytest.MonkeyPatch) -> None:
    tr = transcribe(P.brachistochrone(intervals=20))
    res = tr.solve(P.brachistochrone_guess())
    seen: list[dict[str, object]] = []
    solver = tr.solver

    def spy(options: dict[str, object]) -> object:
        seen.append(dict(options))
        return solver(options)

    monkeypatch.setattr(tr, "solver", spy)
    plain = tr.solve(res, warm_start_multipliers=True, options={"ipopt.mu_init": 1e-2})
    asked = tr.solve(res, warm_start_multipliers=True, options={"ipopt.mu_init": 1e-2},
                     warm_start_options={"ipopt.mu_init": 1e-3})
    cold = tr.solve(P.brachistochrone_guess(), warm_start_multipliers=True,
                    warm_start_options={"ipopt.mu_init": 1e-3})
    assert plain.success and asked.success and cold.success
    assert seen[0] == merge_options(tr.options, WARM_START_OPTIONS)
    assert seen[1]["ipopt.mu_init"] == 1e-3
    assert seen[1]["ipopt.warm_start_init_point"] == "yes"
    assert seen[2] == tr.options  # no multipliers to start from: no warm-start options
    assert asked.objective == pytest.approx(res.objective, rel=1e-8)


def test_user_guess_on_normalised_times() -> None:
    tr = transcribe(P.brachistochrone(intervals=15))
    tau = np.linspace(0, 1, 5)
    guess = Guess(phases={"slide": PhaseGuess(x={"x": tau, "y": 0.6 * tau, "v": 2.0},
                                              u={"theta": 0.5}, tau=tau, duration=0.6)})
    w0 = tr.initial_guess(guess)
    pl = tr.layout.phase("slide")
    np.testing.assert_allclose(w0[pl.across_knots("state", "y")], 0.6 * tr.mesh[0])
    np.testing.assert_allclose(w0[pl.across_knots("state", "v")], 2.0)
    assert w0[pl.duration_index] == 0.6
    res = tr.solve(guess)
    R, _, T = P.cycloid(1.0, 0.6)
    assert res.objective == pytest.approx(T, rel=1e-5)


@pytest.mark.parametrize("mode", ["codegen", "jit"])
def test_compiled_modes_give_the_same_solution(mode: str, tmp_path: object,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    plain = transcribe(P.periodic_ratio(intervals=3)).solve(parameters={"vbar": 1.5})
    tr = transcribe(P.periodic_ratio(intervals=3), compiled=mode, expand=(mode == "jit"))
    res = tr.solve(parameters={"vbar": 1.5})
    assert res.success, res.summary()
    assert res.objective == pytest.approx(plain.objective, rel=1e-10)
    assert res.evaluations["nlp_hess_l"] > 0
    if mode == "codegen":
        # A second build of the same NLP loads the cached library.
        libs = list(tmp_path.glob("ocp_*.so"))  # type: ignore[attr-defined]
        assert len(libs) == 1
        tr2 = transcribe(P.periodic_ratio(intervals=3), compiled=mode)
        assert list(tmp_path.glob("ocp_*.so")) == libs  # type: ignore[attr-defined]
        assert tr2.solve(parameters={"vbar": 1.5}).objective == pytest.approx(res.objective)


def test_mx_evaluation_without_expand() -> None:
    res = transcribe(P.two_phase_jump(4), expand=False).solve()
    assert res.objective == pytest.approx(60.0 / 13.0, rel=1e-9)


def test_path_rows_relax_one_path_constraint_without_rebuilding() -> None:
    limit = 1.2
    tr = transcribe(P.with_path_constraint(20, limit))
    bound = tr.solve()
    rows = tr.path_rows("move", "speed")
    # One row per knot and per midpoint (the constraint is imposed at both).
    assert rows.size == 21 + 20
    assert np.allclose(tr.bounds().ubg[rows], limit)
    free = tr.solve(bounds=tr.bounds().with_rows(rows, -np.inf, np.inf))
    unconstrained = transcribe(P.double_integrator(20)).solve()
    assert bound.success and free.success
    # Relaxed, it is the unconstrained double integrator again (J = 12); bound, it costs more.
    assert free.objective == pytest.approx(unconstrained.objective, rel=1e-8)
    assert bound.objective > free.objective * 1.01
    assert tr.builds["nlp"] == 1
    with pytest.raises(ValueError, match="no path constraint 'nope'"):
        tr.path_rows("move", "nope")


def test_a_solver_with_other_options_shares_the_derivatives() -> None:
    tr = transcribe(P.brachistochrone(intervals=10), options={"ipopt.tol": 1e-10})
    first = tr.solve(P.brachistochrone_guess())
    other = tr.solve(P.brachistochrone_guess(), options={"ipopt.mu_init": 1e-2})
    assert tr.builds["solver"] == 2
    assert other.success and other.objective == pytest.approx(first.objective, rel=1e-8)


def test_a_limited_memory_solver_derives_no_hessian_and_finds_the_same_optimum() -> None:
    """``build_solver=False`` defers the solver to the first solve; a limited-memory solve
    derives no Hessian, and an exact-Hessian solver built afterwards does not try to share
    the Hessian that the limited-memory one never had."""
    lm = {"ipopt.hessian_approximation": "limited-memory"}
    tr = transcribe(P.brachistochrone(intervals=10), options={"ipopt.tol": 1e-10},
                    build_solver=False)
    assert tr.builds["solver"] == 0
    quasi = tr.solve(P.brachistochrone_guess(), options=lm)
    assert tr.builds["solver"] == 1
    assert not tr.solver(merge_options(tr.options, lm)).has_function("nlp_hess_l")
    exact = tr.solve(P.brachistochrone_guess())
    assert tr.solver(tr.options).has_function("nlp_hess_l")
    # A second limited-memory solver with other options shares the first one's functions.
    again = tr.solve(P.brachistochrone_guess(), options={**lm, "ipopt.mu_init": 1e-2})
    assert tr.builds["solver"] == 3
    assert quasi.success and exact.success and again.success
    assert quasi.objective == pytest.approx(exact.objective, rel=1e-7)
    assert again.objective == pytest.approx(exact.objective, rel=1e-7)
    assert exact.iterations < quasi.iterations  # Newton's steps against quasi-Newton's


def test_a_result_of_fewer_constraint_blocks_restarts_with_its_multipliers_by_name() -> None:
    """A solution of the problem without an added constraint (inactive at its optimum)
    restarts the problem with it: the shared blocks' multipliers carried over by name, the
    added block's at 0, and IPOPT finds the same optimum at once; from the values alone it
    takes longer. A result of other variables is refused."""
    import dataclasses

    import casadi as ca

    from gaitopt.ocp import BoundaryConstraint
    from gaitopt.ocp.validate import ProblemError

    base = P.brachistochrone(intervals=20)
    res = transcribe(base).solve(P.brachistochrone_guess())
    assert res.success and res.constraint_blocks
    cap = BoundaryConstraint("final speed cap", lambda ends, p: ends["slide"].xf[2],
                             lower=-ca.inf, upper=10.0)  # the optimum ends at 3.43 m/s
    tr = transcribe(dataclasses.replace(base, boundary_constraints=(cap,)))
    start = tr.carried_over(res)
    added = tr.nlp.constraints.block("final speed cap")
    assert np.all(start.lam_g[added.rows] == 0.0)
    rows, at = {}, 0
    for name, n in res.constraint_blocks:
        rows[name], at = slice(at, at + n), at + n
    shared = [b for b in tr.nlp.constraints.blocks if b.name in rows]
    assert len(shared) == len(res.constraint_blocks)
    for b in shared:
        np.testing.assert_array_equal(start.lam_g[b.rows], res.lam_g[rows[b.name]])
    np.testing.assert_array_equal(start.w, res.w)
    again = tr.solve(res, warm_start_multipliers=True)
    values = tr.solve(res)
    assert again.success and values.success
    assert again.objective == pytest.approx(res.objective, rel=1e-9)
    assert again.iterations <= 3 < values.iterations
    with pytest.raises(ProblemError):
        tr.carried_over(transcribe(P.brachistochrone(intervals=12)).solve(
            P.brachistochrone_guess()))


def test_the_secant_start_predicts_the_next_solution_of_a_smooth_family() -> None:
    """``secant_start`` through the solutions at xf = 1.0 and 1.1 (the brachistochrone's
    end point) lies closer to the solution at 1.2 than the last solution does (values and
    multipliers: a smooth family, so the secant is second-order accurate), and IPOPT
    restarts from it to the same optimum; results of different transcriptions, or an
    infinite ratio, are refused."""
    from gaitopt.ocp import secant_start
    from gaitopt.ocp.validate import ProblemError

    def solved(xf: float) -> object:
        res = transcribe(P.brachistochrone(xf=xf, intervals=20)).solve(
            P.brachistochrone_guess(xf=xf))
        assert res.success
        return res

    a, b, c = solved(1.0), solved(1.1), solved(1.2)
    start = secant_start(a, b, 1.0)  # type: ignore[arg-type]
    np.testing.assert_allclose(start.w, 2.0 * b.w - a.w)  # type: ignore[attr-defined]
    for got, last, want in ((start.w, b.w, c.w), (start.lam_g, b.lam_g, c.lam_g)):  # type: ignore[attr-defined]
        assert np.linalg.norm(got - want) < 0.2 * np.linalg.norm(last - want)
    again = transcribe(P.brachistochrone(xf=1.2, intervals=20)).solve(
        start, warm_start_multipliers=True)
    assert again.success
    assert again.objective == pytest.approx(c.objective, rel=1e-8)  # type: ignore[attr-defined]
    with pytest.raises(ProblemError):
        secant_start(a, transcribe(P.brachistochrone(intervals=12)).solve(  # type: ignore[arg-type]
            P.brachistochrone_guess()), 1.0)
    with pytest.raises(ProblemError):
        secant_start(a, b, float("inf"))  # type: ignore[arg-type]
