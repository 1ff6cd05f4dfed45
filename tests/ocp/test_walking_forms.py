"""The walking problem (the engine's largest user) with both Hermite-Simpson forms.

The separated form must converge where the compressed one does. Without midpoint bounds it is
the compressed NLP with the midpoint states as variables (the same optimum); with them (the
default) its states also respect their bounds at the midpoints, which costs a little on a
coarse grid, and the costs of the two forms converge to the same limit as the grid is refined
(docs/results/benchmarks-gait.md has the table at 8+5 ... 80+20 knots).
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.formulations.reduced.problem import relaxed_bounds, walking_problem
from gaitopt.gait.formulations.step_parameters import Relaxation, parameter_bounds, with_step_time
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.solve.staged import (
    PRIMAL_WARM_OPTIONS,
    StagedRun,
    solve_walking,
    transcription_for,
)
from gaitopt.ocp import transcribe
from gaitopt.robot import load_model
from gaitopt.robot.biped import biped_of

SEPARATED = "hermite-simpson-separated"
MODEL = load_model("five-link")
#: Bound on the relative cost difference of the two forms at 40 + 10 knots (measured 2.6e-4;
#: docs/results/benchmarks-gait.md).
FINE_GAP = 1e-3


def walk(knots: tuple[int, int], form: str, **changes: object) -> StagedRun:
    options = GaitOptions.paper(speed=0.2, knots=knots, transcription=form,  # type: ignore[arg-type]
                          **changes)  # type: ignore[arg-type]
    return solve_walking(MODEL, options)


def test_options_and_cli_accept_the_separated_form_and_name_the_choices() -> None:
    biped = biped_of(MODEL)
    validate_options(GaitOptions.paper(transcription=SEPARATED), biped)
    with pytest.raises(GaitOptionsError, match="transcription = 'simpson'.*"
                                               "'hermite-simpson-separated'"):
        validate_options(GaitOptions.paper(transcription="simpson"),  # type: ignore[arg-type]
                         biped)
    result = CliRunner().invoke(cli, ["solve", "--transcription", "simpson"])
    assert result.exit_code == 2 and "hermite-simpson-separated" in result.output


@pytest.mark.slow
def test_separated_walk_at_8_plus_5_respects_the_state_bounds_between_knots() -> None:
    sep = walk((8, 5), SEPARATED)
    assert sep.success, [s.line() for s in sep.stages]
    res = sep.result
    assert res.method == SEPARATED
    problem = transcription_for(MODEL, sep.options, (8, 5)).problem
    for ph, spec in zip(res.phases, problem.phases, strict=True):
        assert ph.x_mid is not None
        # The midpoint variables are the cubic Hermite midpoints of the knots ...
        np.testing.assert_allclose(ph.x_mid, ph.x_at(0.5 * (ph.t[:-1] + ph.t[1:])), atol=1e-6)
        # ... and they respect the state bounds (the compressed optimum's swing knee does not).
        for name, (lo, hi) in spec.state_bounds.items():
            j = ph.states.index(name)
            assert np.all(ph.x_mid[:, j] >= lo - 1e-7) and np.all(ph.x_mid[:, j] <= hi + 1e-7)


@pytest.mark.slow
def test_without_midpoint_bounds_the_separated_nlp_has_the_compressed_optimum() -> None:
    """``midpoint_bounds=False``: eliminating the midpoint states gives the compressed NLP, so
    the compressed optimum (knots and Hermite midpoints) is optimal for it too."""
    com = walk((8, 5), "hermite-simpson")
    assert com.success
    options = com.options.replace(transcription=SEPARATED)
    problem = walking_problem(MODEL, options)
    tr = transcribe(problem, method=SEPARATED, midpoint_bounds=False,
                    intervals={problem.phases[0].name: 7, problem.phases[1].name: 4},
                    options={"ipopt.tol": options.tol})
    bounds = with_step_time(relaxed_bounds(tr, Relaxation()), options)
    # Started from the values only (the multipliers belong to another layout), with a small
    # barrier as the walking solve's primal warm starts.
    res = tr.solve(com.result, bounds=bounds, parameters=parameter_bounds(options),
                   options=PRIMAL_WARM_OPTIONS)
    assert res.success, res.summary()
    assert res.objective == pytest.approx(com.result.objective, rel=1e-9)
    for a, b in zip(com.result.phases, res.phases, strict=True):
        np.testing.assert_allclose(b.x, a.x, atol=1e-4)


@pytest.mark.slow
def test_both_forms_converge_to_the_same_fine_grid_cost() -> None:
    """With midpoint bounds the separated form is more constrained on a coarse grid (its
    states respect their bounds between knots), so it costs a little more; the difference
    vanishes as the grid is refined (docs/results/benchmarks-gait.md: 8+5 ... 80+20 knots)."""
    gaps = []
    for knots in ((8, 5), (40, 10)):
        com, sep = walk(knots, "hermite-simpson"), walk(knots, SEPARATED)
        assert com.success and sep.success
        gap = sep.result.objective / com.result.objective - 1.0
        # Both reach the same branch here, where the bounded NLP's feasible set (in the knot
        # values) is a subset of the compressed one's: it cannot cost less.
        assert gap > -1e-6
        gaps.append(gap)
    assert gaps[1] < 0.2 * gaps[0]
    assert gaps[1] < FINE_GAP


@pytest.mark.slow
@pytest.mark.parametrize("speed_m_min", [3, 12, 30, 60])
@pytest.mark.parametrize(("ankle", "impulse"), [(True, True), (True, False), (False, True),
                                                (False, False)])
def test_separated_form_converges_from_a_cold_start(speed_m_min: int, ankle: bool,
                                                    impulse: bool) -> None:
    options = GaitOptions.paper(speed=speed_m_min / 60.0, ankle=ankle, impulse=impulse,
                          transcription=SEPARATED)
    sol = solve_walking(MODEL, options)
    assert sol.success, [s.line() for s in sol.stages]
