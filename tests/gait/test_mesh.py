"""Mesh refinement of the walking solve (``GaitOptions.mesh_tol``) and the accuracy record.

The refined solve is checked against what does not come from its own estimates: the verify
re-integration of every interval (an independent ODE solver), the grid it refined from, and
(slow) a much finer uniform grid.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.api import guess_from_gait, solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.record import gait_from_run
from gaitopt.gait.solve.staged import solve_walking
from gaitopt.robot import load_model
from tests.gait.conftest import Solved, SolveFn

TOL = 1e-3
#: The jumps control model: its cost converges on coarse grids (docs/walking.md), so a
#: refinement is quick.
REFINED = GaitOptions(knots=(8, 5), control_model="jumps", mesh_tol=TOL)
INTERVAL_CHECK = "integration.interval"


def _absolute_interval_error(gait: Gait) -> float:
    """verify's re-integration error per interval in absolute terms (rad|m, rates / 10): the
    check reports it so for a file without the grid's own error estimates."""
    data = gait.to_dict()
    for ph in data["phases"]:
        ph.pop("error_estimate", None)
    return verify_gait(Gait.from_dict(data)).check(INTERVAL_CHECK).value


@pytest.fixture(scope="module")
def refined(solved: SolveFn) -> Solved:
    return solved(REFINED)


def test_refinement_meets_the_tolerance_on_a_non_uniform_mesh(refined: Solved) -> None:
    sol = refined.solution
    assert sol.success
    names = [s.name for s in sol.stages]
    assert "mesh refinement 1" in names and names[-1] == "mesh check (halved), all free"
    for ph in sol.result.phases:
        assert np.max(ph.error) <= TOL
    steps = np.diff(sol.result.phases[0].tau)
    assert steps.max() > 1.5 * steps.min()  # refined where the error was: not uniform
    acc = refined.gait.solver["accuracy"]
    assert acc["mesh_tol"] == TOL and acc["mesh_converged"] is True
    for ph in sol.result.phases:
        assert acc["collocation_error"][ph.name] == pytest.approx(float(np.max(ph.error)))
        assert acc["knots"][ph.name] == ph.t.size


def test_the_last_round_halves_every_interval_of_the_mesh_before(refined: Solved) -> None:
    acc = refined.gait.solver["accuracy"]
    res = refined.solution.result
    for ph in res.phases:
        previous = acc["previous_knots"][ph.name]
        assert ph.t.size == 2 * previous - 1
    assert acc["cost_error"] == pytest.approx(res.objective - acc["previous_cost"], abs=1e-9)


def test_refinement_reduces_the_true_interval_error(refined: Solved, solved: SolveFn) -> None:
    """The verify re-integration (an independent ODE solver, knot to knot) agrees much better
    with the refined gait than with the 8 + 5 one of the same problem."""
    coarse = solved(REFINED.replace(mesh_tol=None))
    fine_err = _absolute_interval_error(refined.gait)
    coarse_err = _absolute_interval_error(coarse.gait)
    assert fine_err < coarse_err / 10.0
    assert verify_gait(refined.gait).passed


def test_accuracy_and_the_mesh_survive_save_and_load(refined: Solved, tmp_path: Path) -> None:
    path = refined.gait.save(tmp_path / "refined.gait.json")
    loaded = Gait.load(path)
    assert dict(loaded.solver["accuracy"]) == dict(refined.gait.solver["accuracy"])
    for a, b in zip(loaded.phases, refined.gait.phases, strict=True):
        np.testing.assert_array_equal(a.t, b.t)
    assert GaitOptions.from_dict(dict(loaded.options)) == REFINED


def test_a_gait_file_without_accuracy_still_loads(default_gait: Gait) -> None:
    data = copy.deepcopy(default_gait.to_dict())
    del data["solver"]["accuracy"]
    for key in ("mesh_tol", "control_model", "swing_clearance", "clearance_profile"):
        del data["options"][key]
    old = Gait.from_dict(data)
    assert "accuracy" not in old.solver
    assert GaitOptions.from_dict(dict(old.options)) == GaitOptions.paper()


def test_a_fixed_grid_has_no_cost_error_estimate(default_gait: Gait) -> None:
    acc = default_gait.solver["accuracy"]
    assert acc["mesh_tol"] is None and acc["mesh_converged"] is None
    assert acc["cost_error"] is None and acc["previous_knots"] is None
    assert acc["knots"] == {"single_support": 8, "double_support": 5}
    assert all(0.0 < e < 1.0 for e in acc["collocation_error"].values())


def test_a_warm_start_keeps_the_refined_mesh(refined: Solved) -> None:
    """Started on the gait's mesh before its halving round (every other knot), the solve
    meets the tolerance there and ends on the gait's own mesh: the size does not double."""
    model = load_model("five-link")
    guess = guess_from_gait(refined.gait)
    again = solve_walking(model, REFINED, warm_start=guess)
    assert again.success
    first = again.stages[0]
    assert first.name == "warm start"
    assert first.knots == tuple((ph.t.size + 1) // 2 for ph in refined.gait.phases)
    for ph, old in zip(again.result.phases, refined.gait.phases, strict=True):
        np.testing.assert_allclose(ph.tau, (old.t - old.t[0]) / (old.t[-1] - old.t[0]),
                                   atol=1e-12)
    assert again.result.objective == pytest.approx(refined.solution.result.objective,
                                                   rel=1e-5)
    # Without mesh_tol a warm start is solved on options.knots.
    fixed = solve_walking(model, REFINED.replace(mesh_tol=None), warm_start=guess)
    assert fixed.stages[0].knots == (8, 5)


@pytest.mark.slow
def test_the_cost_error_estimate_bounds_the_difference_to_a_fine_grid() -> None:
    """The refined cost (mesh_tol 1e-4) differs from the cost on a uniform 160 + 40 grid by
    less than its reported estimate."""
    options = GaitOptions(knots=(8, 5), control_model="jumps", mesh_tol=1e-4)
    refined = solve_staged_run("five-link", options)
    fine = solve_staged_run("five-link", options.replace(mesh_tol=None, knots=(160, 40)))
    assert refined.success and fine.success
    acc = gait_from_run(refined).solver["accuracy"]
    gap = abs(refined.result.objective - fine.result.objective)
    print(f"refined {refined.result.objective:.4f} (estimate {acc['cost_error']:+.4f}), "
          f"160 + 40: {fine.result.objective:.4f}")
    assert math.isfinite(acc["cost_error"])
    assert gap <= abs(acc["cost_error"])
