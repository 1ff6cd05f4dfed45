"""Control models (``GaitOptions.control_model``): the paper's control linkages, or none
("jumps"), each converging at 12 m/min on the paper's 8 + 5 grid."""

from __future__ import annotations

import numpy as np
import pytest

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve.staged import transcription_for
from gaitopt.robot import load_model
from tests.gait.conftest import Solved, SolveFn

CONTINUITY = "controls continuous at heel strike"
PERIODICITY = "controls periodic (legs relabelled)"


@pytest.fixture(scope="module")
def jumps(solved: SolveFn) -> Solved:
    return solved(GaitOptions(knots=(8, 5), control_model="jumps"))


def block_names(options: GaitOptions) -> set[str]:
    tr = transcription_for(load_model("five-link"), options, options.knots)
    return {b.name for b in tr.nlp.constraints.blocks}


def test_only_the_paper_model_links_the_controls() -> None:
    paper = block_names(GaitOptions.paper())
    assert CONTINUITY in paper and PERIODICITY in paper
    assert CONTINUITY in block_names(GaitOptions.paper(periodic_controls=False))
    assert PERIODICITY not in block_names(GaitOptions.paper(periodic_controls=False))
    free = block_names(GaitOptions(knots=(8, 5), control_model="jumps"))
    assert CONTINUITY not in free and PERIODICITY not in free


def heel_strike_jump(solved_: Solved) -> float:
    """Largest change (N m) of a torque that acts in both phases across the heel strike."""
    first, second = solved_.gait.phases
    before, after = first.u[-1], second.u[0]
    both = (np.abs(before) > 0) & (np.abs(after) > 0)
    return float(np.max(np.abs(after[both] - before[both])))


def test_each_control_model_converges_at_12_m_min_on_8_plus_5(
        jumps: Solved, default_solved: Solved) -> None:
    for s in (jumps, default_solved):
        assert s.solution.success
        assert s.gait.parameters["speed"] == pytest.approx(0.2)
        assert verify_gait(s.gait).passed
    assert heel_strike_jump(default_solved) < 1e-6
    # Free to jump, the optimal torques do (else the model changed nothing).
    assert heel_strike_jump(jumps) > 1e-2


def test_dropping_the_linkages_cannot_raise_the_optimum(
        jumps: Solved, default_solved: Solved) -> None:
    """The jumps model relaxes the paper's: its optimum on the same grid is no higher (the
    paper's optimum is feasible for it)."""
    assert jumps.solution.result.objective <= default_solved.solution.result.objective
    assert jumps.gait.options["control_model"] == "jumps"
