"""The gait record's costates (gaitopt.gait.solve.costates) on the paper's default gait."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.costates import solution_costates
from gaitopt.gait.solve.transcriptions import transcription_for
from gaitopt.ocp import costates
from tests.gait.conftest import Solved


def test_the_record_carries_the_final_solves_costates(default_solved: Solved) -> None:
    sol, gait = default_solved.solution, default_solved.gait
    res = sol.result
    tr = transcription_for(sol.model, sol.options, tuple(m.size for m in res.mesh))
    expected = costates(tr, res)
    assert set(expected) == {ph.name for ph in gait.phases}
    for ph in gait.phases:
        assert ph.costates is not None
        assert ph.costates.shape == (ph.t.size, len(ph.state_names))
        np.testing.assert_array_equal(ph.costates, expected[ph.name])
    assert solution_costates(sol).keys() == expected.keys()


def test_the_costates_survive_the_file(default_gait_file: Path) -> None:
    gait = Gait.load(default_gait_file)
    assert all(ph.costates is not None and np.all(np.isfinite(ph.costates))
               for ph in gait.phases)


def test_a_single_support_step_with_knots_by_phase_name_has_costates() -> None:
    # The step's one phase's knots given by name: the options hold one count (this raised an
    # IndexError when the record looked for a second phase's).
    from gaitopt import GaitOptions, solve_gait

    options = GaitOptions(speed=0.5, step_length=0.3, single_support_fraction=1.0,
                          knots={"single_support": 8}, knot_spacing="uniform")
    gait = solve_gait("five-link", options)
    assert gait.success
    (phase,) = gait.phases
    assert phase.costates is not None
    assert phase.costates.shape == (8, len(phase.state_names))
    assert np.all(np.isfinite(phase.costates))
