"""Another topology through the same mechanism: a knee-less biped (a torso on two rigid legs
with point tips, hip torques only; ``tests/gait/data/compass.yaml``). It has no thigh-shank
legs, so it takes the generic guess (:mod:`gaitopt.gait.guess.sequence`); its gaits are
checked against Pinocchio's equations of motion at every knot and by verify."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml

from gaitopt.analysis.checks.check import LIMITS
from gaitopt.analysis.verify import verify_gait
from gaitopt.dynamics.kinematics import contact_position
from gaitopt.gait.api import solve_gait
from gaitopt.gait.formulations.select import biped_for, contact_sequence
from gaitopt.gait.guess.sequence import sequence_guess
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError
from gaitopt.robot import load_model, model_from_dict
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import leg_swap
from tests.gait.conftest import (
    Reference,
    Solved,
    assert_physics,
    periodicity_errors,
    recomputed_cost,
)

COMPASS = Path(__file__).parent / "data" / "compass.yaml"
SolveFn = Callable[..., Solved]
RefFn = Callable[[RobotModel], Reference]


@pytest.fixture(scope="module")
def compass() -> RobotModel:
    return load_model(str(COMPASS))


def test_the_model_has_no_knees_and_takes_the_generic_guess(compass: RobotModel) -> None:
    """Five coordinates (base x, y, torso angle, two hips), two actuators, the leg swap
    inferred from the names; the generic guess holds tip 1 at x = 0 through single support
    and puts tip 2 one step ahead at the heel strike."""
    assert compass.nq == 5 and [a.name for a in compass.actuators] == ["hip_1", "hip_2"]
    options = GaitOptions(formulation="full")
    assert biped_for(compass, options) is None
    assert dict(leg_swap(compass).contacts) == {"tip_1": "tip_2", "tip_2": "tip_1"}
    step = 0.25
    guess = sequence_guess(compass, contact_sequence(compass, options),
                           leg_swap(compass).contacts, speed=0.2, step_length=step,
                           knots=(8, 5), ankle=True)
    single = guess.phases[0]
    for x in single.x:
        tip = np.asarray(contact_position(compass, x[:5], "tip_1"), dtype=float).ravel()
        np.testing.assert_allclose(tip, [0.0, 0.0], atol=2e-3)
    landing = np.asarray(contact_position(compass, single.x[-1][:5], "tip_2"), float).ravel()
    np.testing.assert_allclose(landing, [step, 0.0], atol=2e-3)


def test_the_paper_walk_of_a_knee_less_biped(solved: SolveFn, reference: RefFn) -> None:
    """12 m/min, 16+6 knots, liftoff impulse on, from the naive start: converged; Pinocchio's
    equations of motion hold at every knot with the saved forces, the held tips stay put,
    the step is periodic with the legs swapped, the cost is the controls', verify passes,
    comparing the re-integration with each interval's error estimate, which the
    full-coordinate record carries (not the fixed limit of files without one)."""
    gait = solved(GaitOptions(formulation="full"), str(COMPASS)).gait
    assert gait.success
    assert_physics(reference(gait.model), gait)
    state, control = periodicity_errors(gait, controls=())
    assert state < 1e-6
    assert recomputed_cost(gait) == pytest.approx(gait.cost_value, rel=1e-6)
    for ph in gait.phases:
        assert ph.error_estimate is not None and ph.error_estimate.shape == (ph.t.size - 1,)
        assert np.all(ph.error_estimate > 0)
    report = verify_gait(gait)
    assert report.passed, report.failed_ids
    assert report.check("integration.interval").limit == LIMITS["integration.interval"]


def test_a_knee_less_walk_with_free_phase_fractions(solved: SolveFn, reference: RefFn) -> None:
    """The same walk with both phase shares free: converged, physical (Pinocchio), verify
    passes, and not above the fixed shares' cost."""
    fixed = solved(GaitOptions(formulation="full"), str(COMPASS)).gait
    gait = solved(GaitOptions(formulation="full", free_phase_fractions=True),
                  str(COMPASS)).gait
    assert gait.success
    assert_physics(reference(gait.model), gait)
    assert gait.cost_value <= fixed.cost_value * (1 + 1e-6)
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


def test_a_step_the_legs_cannot_reach_is_a_clear_error(tmp_path: Path) -> None:
    """Legs of 0.3 m cannot make a 0.75 m step: the step length bounds that follow the model
    (0.8 m on 1 m legs: 0.24 m) refuse it; with the bounds widened by hand the generic guess
    says which point it cannot hold where, and the solve stops with a one-line error before
    any NLP."""
    data = yaml.safe_load(COMPASS.read_text())
    for link in data["links"][1:]:
        link["length"], link["com"] = 0.3, [0.15, 0.0]
    for contact in data["contacts"]:
        contact["at"] = [0.3, 0.0]
    model = model_from_dict(data)
    with pytest.raises(GaitOptionsError, match=r"targets.step_length = 0.75 m: must lie in "
                       r"targets.step_length_bounds \[0.006, 0.24\] m"):
        solve_gait(model, GaitOptions(formulation="full", step_length=0.75))
    with pytest.raises(GaitOptionsError, match=r"targets.step_length = 0.75 m: every naive "
                       r"start puts a leg beyond its reach \(the legs of model 'compass' "
                       r"cannot hold 'tip_1'.*misses it by 0.0"):
        solve_gait(model, GaitOptions(formulation="full", step_length=0.75, speed=0.2,
                                      step_length_bounds=(0.02, 0.8)))


def test_the_documented_model_is_this_one(compass: RobotModel) -> None:
    """docs/formulations.md shows the model file; it is the one these tests solve."""
    text = (Path(__file__).parents[2] / "docs" / "formulations.md").read_text()
    block = text.split("```yaml\nformat: gaitopt.model\n", 1)[1].split("```", 1)[0]
    documented = model_from_dict(yaml.safe_load("format: gaitopt.model\n" + block))
    mine, theirs = compass.to_dict(), documented.to_dict()
    for data in (mine, theirs):
        data.pop("description", None)
    assert theirs == mine
