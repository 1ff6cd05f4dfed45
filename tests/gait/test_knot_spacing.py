"""Cosine-spaced knots (``GaitOptions.knot_spacing``): the mesh, the target grid of a solve,
and (slow) that it converges at fast walks where the uniform grid converges at first order."""

from __future__ import annotations

import numpy as np
import pytest

from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.solve.staged import solve_walking
from gaitopt.gait.solve.transcriptions import cosine_knots, target_grid
from gaitopt.robot import load_model
from gaitopt.robot.biped import reduced_biped


def test_cosine_knots_cluster_at_both_ends() -> None:
    n = 16
    tau = cosine_knots(n)
    assert tau[0] == 0.0 and tau[-1] == pytest.approx(1.0)
    np.testing.assert_allclose(tau + tau[::-1], 1.0, atol=1e-15)  # symmetric
    h = np.diff(tau)
    assert np.all(h > 0)
    # end interval (1 - cos(pi / (n - 1))) / 2, middle sin(pi / (2 (n - 1))) about the phase
    assert h[0] == pytest.approx((1 - np.cos(np.pi / (n - 1))) / 2)
    assert h.max() == pytest.approx(np.sin(np.pi / (2 * (n - 1))), rel=1e-12)
    assert h.max() / h[0] > 9


def test_target_grid() -> None:
    model = load_model("five-link")
    assert target_grid(model, GaitOptions(knot_spacing="uniform")) == (16, 6)
    assert GaitOptions().knot_spacing == "cosine" == GaitOptions.paper(knot_spacing="cosine"
                                                                       ).knot_spacing
    ss, ds = target_grid(model, GaitOptions(knot_spacing="cosine", knots=(24, 8)))
    np.testing.assert_array_equal(ss, cosine_knots(24))
    np.testing.assert_array_equal(ds, cosine_knots(8))
    alone = target_grid(model, GaitOptions(knot_spacing="cosine",
                                           single_support_fraction=1.0))
    assert len(alone) == 1


def test_a_bad_spacing_names_the_field() -> None:
    model = load_model("five-link")
    with pytest.raises(GaitOptionsError, match="knot_spacing = 'chebyshev': must be one of "
                                               "'uniform', 'cosine'"):
        validate_options(GaitOptions(knot_spacing="chebyshev"),  # type: ignore[arg-type]
                         reduced_biped(model))


@pytest.mark.slow
def test_cosine_knots_converge_where_uniform_ones_do_not() -> None:
    """45 m/min without ankle torques (docs/walking.md section 6): from 16 + 6 to 48 + 12
    knots the uniform grid's cost rises by more than 2 % (first order), the cosine grid's by
    less than 1 %, and the cosine 16 + 6 cost is nearer the finest value."""
    model = load_model("five-link")
    base = GaitOptions(speed=0.75, ankle=False, impulse=False)
    start = solve_walking(model, base)
    assert start.success
    cost = {}
    for spacing in ("uniform", "cosine"):
        for knots in ((16, 6), (48, 12)):
            sol = solve_walking(model, base.replace(knots=knots, knot_spacing=spacing),
                                warm_start=start.result)
            assert sol.success
            cost[spacing, knots[0]] = sol.result.objective
    assert cost["uniform", 48] / cost["uniform", 16] - 1 > 0.02
    assert abs(cost["cosine", 48] / cost["cosine", 16] - 1) < 0.01
    finest = max(cost["uniform", 48], cost["cosine", 48])
    assert abs(cost["cosine", 16] - finest) < abs(cost["uniform", 16] - finest)


def test_cosine_grid_of_a_four_phase_sequence() -> None:
    """Cosine spacing follows the problem's phases: the heel-toe walk's four phases get their
    own knot counts (the density rule), and the transcription builds on that mesh."""
    from gaitopt.gait.formulations.select import contact_sequence
    from gaitopt.gait.sequence.contact_sequence import phase_knots
    from gaitopt.gait.solve.transcriptions import transcription_for

    model = load_model("seven-link")
    options = GaitOptions(formulation="full", gait="heel-toe", knots=(8, 5),
                          knot_spacing="cosine")
    grid = target_grid(model, options)
    counts = phase_knots(contact_sequence(model, options), options.knots)
    assert [len(m) for m in grid] == list(counts) and len(grid) == 4
    for mesh, n in zip(grid, counts, strict=True):
        np.testing.assert_array_equal(mesh, cosine_knots(n))
    tr = transcription_for(model, options, grid)
    for mesh, n in zip(tr.mesh, counts, strict=True):
        np.testing.assert_allclose(np.asarray(mesh, dtype=float), cosine_knots(n))
