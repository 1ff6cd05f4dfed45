"""The layout names the flat NLP vectors; the NLP size is counted in the paper's terms."""

from __future__ import annotations

import numpy as np
import problems as P
import pytest

from gaitopt.ocp import transcribe


def test_variable_layout_of_a_two_phase_problem_with_parameters() -> None:
    tr = transcribe(P.periodic_ratio(intervals=4))
    lay = tr.layout
    first, second = lay.phase("first"), lay.phase("second")
    # Expression durations have no variable; 5 knots x (2 states + 1 control) per phase.
    assert first.duration_index is None and second.duration_index is None
    assert (first.start, first.end, second.start, second.end) == (0, 15, 15, 30)
    assert lay.parameters == ("D", "vbar") and lay.parameter_start == 30 and lay.size == 32
    assert lay.index("second", "control", "a", 2) == 15 + 2 * 3 + 2
    assert lay.index("first", "state", "v", -1) == 4 * 3 + 1
    assert lay.index(0, "parameter", "vbar") == 31
    np.testing.assert_array_equal(first.state_indices()[:, 1],
                                  np.arange(15)[first.across_knots("state", "v")])
    with pytest.raises(KeyError, match="no state 'q'"):
        first.index("state", "q", 0)
    with pytest.raises(IndexError, match="knot 5 out of range"):
        first.index("state", "s", 5)


def test_layout_reads_the_solution_vector() -> None:
    res = transcribe(P.brachistochrone(intervals=8)).solve(P.brachistochrone_guess())
    tr = transcribe(P.brachistochrone(intervals=8))
    pl = tr.layout.phase("slide")
    ph = res.phase("slide")
    np.testing.assert_array_equal(res.w[pl.across_knots("state", "y")], ph.state("y"))
    np.testing.assert_array_equal(res.w[pl.across_knots("control", "theta")], ph.control("theta"))
    assert res.w[pl.duration_index] == pytest.approx(ph.duration)


def test_nlp_size_and_constraint_blocks() -> None:
    tr = transcribe(P.periodic_ratio(intervals=4))
    size = tr.nlp_size()
    # 2 phases x 5 knots x 3 + 2 parameters = 32 variables; D fixed, s(0) fixed.
    # v in [-10, 10] at 10 knots and vbar bounded: 11 box-bounded.
    assert (size.variables, size.fixed_variables, size.box_bounded_variables) == (32, 2, 11)
    # Equalities: 2 x 4 intervals x 2 defects, linkages 2 + 1 + 1 + 1 (states, controls,
    # cyclic v, cyclic a), distance 1.
    assert size.equality_constraints == 16 + 5 + 1
    assert size.inequality_constraints == 0
    cons = tr.nlp.constraints
    assert cons.block("first/defects").shape == (4, 2)
    assert cons.block("cyclic v").rows.stop - cons.block("cyclic v").rows.start == 1
    assert cons.size == 22 and len(cons.row_names()) == 22
    path = transcribe(P.with_path_constraint(10)).nlp_size()
    assert path.inequality_constraints == 11 + 10  # knots + midpoints


def test_scales_from_bounds_and_given_scales_leave_the_answer_unchanged() -> None:
    from dataclasses import replace

    from gaitopt.ocp import Problem

    base = P.free_time(8)
    ph = replace(base.phases[0], state_bounds={"s": (-2.0, 1000.0)}, control_scales={"a": 20.0})
    prob = Problem([ph], mayer=base.mayer)
    tr = transcribe(prob)
    pl = tr.layout.phase(0)
    d = tr.nlp.d_w
    np.testing.assert_allclose(d[pl.across_knots("state", "s")], 1000.0)  # largest bound
    np.testing.assert_allclose(d[pl.across_knots("state", "v")], 1.0)  # unbounded
    np.testing.assert_allclose(d[pl.across_knots("control", "a")], 20.0)  # given
    assert d[pl.duration_index] == 10.0  # duration bounds (0.5, 10)
    # Defects take their state's scale.
    rows = tr.nlp.constraints.block("move/defects").rows
    np.testing.assert_allclose(tr.nlp.d_g[rows].reshape(8, 2), [[1000.0, 1.0]] * 8)
    scaled, plain = tr.solve(), transcribe(prob, scaling=False).solve()
    assert scaled.objective == pytest.approx(plain.objective, rel=1e-8)
    assert scaled.objective == pytest.approx(8.0 / 6.0**0.5, rel=1e-8)
