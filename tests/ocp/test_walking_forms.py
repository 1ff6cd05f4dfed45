"""The walking problem (the engine's largest user) with both Hermite-Simpson forms.

The separated form must converge where the compressed one does and reach the same optimum:
eliminating its midpoint states gives the compressed NLP back, so on every grid the costs agree
to the solver's tolerance (docs/benchmarks-gait.md has the table at 8+5 ... 80+20 knots).
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.problem import parameter_bounds
from gaitopt.gait.solve import WalkingSolution, solve_walking, transcription_for
from gaitopt.robot import load_model
from gaitopt.robot.biped import biped_structure

SEPARATED = "hermite-simpson-separated"
MODEL = load_model("five-link")


def walk(knots: tuple[int, int], form: str, **changes: object) -> WalkingSolution:
    options = GaitOptions(speed=0.2, knots=knots, transcription=form,  # type: ignore[arg-type]
                          **changes)  # type: ignore[arg-type]
    return solve_walking(MODEL, options)


def test_options_and_cli_accept_the_separated_form_and_name_the_choices() -> None:
    biped = biped_structure(MODEL)
    validate_options(GaitOptions(transcription=SEPARATED), biped)
    with pytest.raises(GaitOptionsError, match="transcription = 'simpson'.*"
                                               "'hermite-simpson-separated'"):
        validate_options(GaitOptions(transcription="simpson"),  # type: ignore[arg-type]
                         biped)
    result = CliRunner().invoke(cli, ["solve", "--transcription", "simpson"])
    assert result.exit_code == 2 and "hermite-simpson-separated" in result.output


@pytest.mark.slow
def test_separated_walk_at_8_plus_5_converges_to_a_point_of_the_compressed_nlp() -> None:
    """The separated optimum's knots, put into the compressed form's NLP (built, not
    solved), satisfy its constraints and give the same cost: the same discretisation."""
    sep = walk((8, 5), SEPARATED)
    assert sep.success, [s.line() for s in sep.stages]
    res = sep.result
    assert res.method == SEPARATED
    options = sep.options.replace(transcription="hermite-simpson")
    tr = transcription_for(MODEL, options, (8, 5))
    w = tr.initial_guess(res)
    g, num, den, _ = (np.asarray(v, dtype=float).ravel() for v in tr.nlp.evaluate(w))
    b = tr.bounds()
    for name, (lo, hi) in parameter_bounds(options).items():
        b = b.with_parameter(name, lo, hi)
    scale = tr.nlp.d_g
    violation = np.max(np.maximum(b.lbg - g, g - b.ubg) / scale)
    assert violation < 1e-6
    assert float(num[0] / den[0]) == pytest.approx(res.objective, rel=1e-9)
    # The midpoint variables are the compressed form's cubic Hermite midpoints.
    for ph in res.phases:
        assert ph.x_mid is not None
        mid = 0.5 * (ph.t[:-1] + ph.t[1:])
        np.testing.assert_allclose(ph.x_mid, ph.x_at(mid), atol=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("knots", [(8, 5), (40, 10)])
def test_both_forms_reach_the_same_walking_optimum(knots: tuple[int, int]) -> None:
    com, sep = walk(knots, "hermite-simpson"), walk(knots, SEPARATED)
    assert com.success and sep.success
    assert sep.result.objective == pytest.approx(com.result.objective, rel=1e-6)
    assert sep.result.parameters["step_length"] == pytest.approx(
        com.result.parameters["step_length"], rel=1e-5)


@pytest.mark.slow
@pytest.mark.parametrize("speed_m_min", [3, 12, 30, 60])
@pytest.mark.parametrize(("ankle", "impulse"), [(True, True), (True, False), (False, True),
                                                (False, False)])
def test_separated_form_converges_from_a_cold_start(speed_m_min: int, ankle: bool,
                                                    impulse: bool) -> None:
    options = GaitOptions(speed=speed_m_min / 60.0, ankle=ankle, impulse=impulse,
                          transcription=SEPARATED)
    sol = solve_walking(MODEL, options)
    assert sol.success, [s.line() for s in sol.stages]
