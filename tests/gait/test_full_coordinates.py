"""The full-coordinate formulation: it converges, its gaits are physically right (checked with
Pinocchio, independent of gaitopt's dynamics), it agrees with the reduced formulation, and it
lets a stance knee straighten, which the reduced one cannot."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.api import solve_gait
from gaitopt.gait.formulations.full.physics import state_names
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.builtin import running_sequence, walking_sequence
from gaitopt.gait.sequence.contact_sequence import (
    ContactSequence,
    ContactSequenceError,
    PhaseSpec,
    check_sequence,
)
from gaitopt.robot import load_model, model_from_dict
from gaitopt.robot.biped import biped_of
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import leg_swap
from tests.gait.conftest import (
    Reference,
    Solved,
    assert_physics,
    periodicity_errors,
    recomputed_cost,
)

RefFn = Callable[[RobotModel], Reference]
SolveFn = Callable[..., Solved]

FULL = GaitOptions.paper(formulation="full")


def test_paper_problem_in_full_coordinates_is_physical(solved: SolveFn,
                                                       reference: RefFn) -> None:
    """12 m/min, ankle torques and impulse: converged, Pinocchio's equations of motion hold at
    every knot with the saved forces, held tips stay put to 1e-6 m, the step is periodic with
    the legs swapped, and the saved cost is the controls' (independent quadrature)."""
    gait = solved(FULL).gait
    assert gait.success and gait.solver["max_violation"] < 1e-6
    ph = gait.phases[0]
    assert ph.state_names == state_names(gait.model)
    np.testing.assert_allclose(ph.x, np.hstack([ph.q, ph.qd]))
    assert_physics(reference(gait.model), gait)
    state, control = periodicity_errors(gait, controls=("hip_1", "knee_1", "hip_2", "knee_2"))
    assert state < 1e-6 and control < 1e-6
    assert recomputed_cost(gait) == pytest.approx(gait.cost_value, rel=1e-6)
    assert verify_gait(gait).passed


def test_both_formulations_agree_on_the_paper_grid(solved: SolveFn) -> None:
    """They discretise different coordinates, so on the coarse 8+5 grid they differ by the
    discretization error only (a few per cent; the fine-grid table is in docs/walking.md)."""
    full, reduced = solved(FULL).gait, solved(GaitOptions.paper()).gait
    assert full.cost_value == pytest.approx(reduced.cost_value, rel=0.03)
    assert full.step_length == pytest.approx(reduced.step_length, rel=0.03)


@pytest.mark.slow
@pytest.mark.parametrize("ankle", [True, False])
@pytest.mark.parametrize("impulse", [True, False])
def test_formulations_agree_on_a_fine_grid(ankle: bool, impulse: bool) -> None:
    """On 40+10 knots the two formulations' optima agree to 1 % (cost) and 2 % (step)."""
    base = GaitOptions.paper(ankle=ankle, impulse=impulse, knots=(40, 10))
    reduced = solve_gait("five-link", base)
    full = solve_gait("five-link", base.replace(formulation="full"))
    assert reduced.success and full.success
    assert full.cost_value == pytest.approx(reduced.cost_value, rel=0.01)
    assert full.step_length == pytest.approx(reduced.step_length, rel=0.02)


def test_stance_knee_may_straighten(solved: SolveFn, reference: RefFn) -> None:
    """With no knee margin the optimum rests on the straight stance knee (the joint limit 0),
    which the reduced formulation cannot represent; it is much cheaper, and still physical."""
    bent = solved(FULL).gait
    gait = solved(FULL.replace(min_stance_knee_flexion=0.0)).gait
    assert gait.success
    assert_physics(reference(gait.model), gait)
    knee = gait.model.joint_coordinate("knee_1")
    stance_knee = np.concatenate([ph.q[:, knee] for ph in gait.phases])
    assert stance_knee.max() > -1e-4  # reaches the straight knee
    assert stance_knee.max() <= 1e-7  # never bends backwards
    assert gait.cost_value < 0.9 * bent.cost_value
    assert verify_gait(gait).passed


def _other_biped() -> RobotModel:
    """A thigh-shank biped unlike the paper's: other masses, lengths, COM offsets, inertias."""
    data = load_model("five-link").to_dict()
    for link in data["links"]:
        link.pop("shape", None)
        if link["name"] == "torso":
            link.update(mass=30.0, length=0.6, com=[0.2, 0.0], inertia=0.9)
        elif link["name"].startswith("thigh"):
            link.update(mass=8.0, length=0.45, com=[0.18, 0.0], inertia=0.12)
        else:
            link.update(mass=3.0, length=0.55, com=[0.3, 0.0], inertia=0.08)
            link["joint"]["at"] = [0.45, 0.0]
    for c in data["contacts"]:
        c["at"] = [0.55, 0.0]
    data["name"] = "other-biped"
    return model_from_dict(data)


@pytest.mark.parametrize("model", [load_model("five-link"), _other_biped()],
                         ids=["five-link", "other-biped"])
def test_single_support_gait_with_a_straight_knee(model: RobotModel, reference: RefFn) -> None:
    """The single-support gait (no double support) with fixed step length and time, states
    periodic only, no ankle torques, knee margin 0: converges from a naive start and is
    physical."""
    options = GaitOptions.paper(formulation="full", single_support_fraction=1.0, ankle=False,
                          impulse=False, periodic_controls=False, min_stance_knee_flexion=0.0,
                          speed=0.3, step_length=0.2)
    gait = solve_gait(model, options)
    assert gait.success, gait.status
    assert gait.step_length == pytest.approx(0.2) and gait.speed == pytest.approx(0.3)
    assert_physics(reference(model), gait)
    assert verify_gait(gait).passed


def _biped_with_arms() -> RobotModel:
    """Another topology: the five-link biped with a sixth link, an actuated arm hanging from
    the top of the torso (4 kg taken from the torso); 8 coordinates."""
    data = load_model("five-link").to_dict()
    data["name"] = "six-link-arm"
    data["links"][0]["mass"] = 16.0
    del data["links"][0]["shape"]  # keep the torso's inertia (0.576 kg m^2)
    data["links"].append({
        "name": "arm", "parent": "torso", "direction": "down", "length": 0.6, "mass": 4.0,
        "com": [0.3, 0.0], "inertia": 0.12,
        "joint": {"name": "shoulder", "at": [0.72, 0.0], "limits": [-1.5, 1.5]}})
    data["actuators"].append({"name": "shoulder", "joint": "shoulder", "limits": [-30.0, 30.0]})
    return model_from_dict(data)


def test_another_topology_walks_through_the_same_mechanism(reference: RefFn) -> None:
    """A torso with an extra actuated link (which the reduced formulation cannot describe)
    walks at 12 m/min from the naive start; its gait is physical and periodic, the arm's
    coordinate and torque included."""
    model = _biped_with_arms()
    assert model.nq == 8
    gait = solve_gait(model, FULL)
    assert gait.success, gait.status
    assert_physics(reference(model), gait)
    state, control = periodicity_errors(
        gait, controls=("hip_1", "knee_1", "hip_2", "knee_2", "shoulder"))
    assert state < 1e-6 and control < 1e-6
    assert verify_gait(gait).passed


def test_warm_start_from_a_full_gait_file(solved: SolveFn, tmp_path) -> None:  # noqa: ANN001
    gait = solved(FULL).gait
    path = gait.save(tmp_path / "full.gait.json")
    again = solve_gait("five-link", FULL, warm_start=Gait.load(path))
    assert again.success
    assert again.solver["stages"][0]["name"] == "warm start"
    assert again.cost_value == pytest.approx(gait.cost_value, rel=1e-5)


def test_contact_sequences_are_one_mechanism() -> None:
    model = load_model("five-link")
    swap = dict(leg_swap(model).contacts)
    for seq in (walking_sequence(model, 0.85, impulse=True),
                walking_sequence(model, 1.0, impulse=False), running_sequence(model, 0.4)):
        check_sequence(model, seq, swap)  # consistent: each event leads into the next phase
    walk = walking_sequence(model, 0.85, impulse=True)
    assert walk.held_after(0) == ("tip_1", "tip_2")
    assert walk.held_after(1) == ("tip_2",)  # swapped: tip_1 of the next step
    broken = ContactSequence("broken", (PhaseSpec("a", ("tip_1",), 0.5),
                                        PhaseSpec("b", ("tip_1", "tip_2"), 0.5)),
                             walk.events[:1] * 2, walk.anchors)
    with pytest.raises(ContactSequenceError, match="touches down 'tip_2', which is held"):
        check_sequence(model, broken, swap)
    bad = ContactSequence("bad", (PhaseSpec("a", ("heel",), 1.0),), walk.events[:1],
                          walk.anchors)
    with pytest.raises(ContactSequenceError, match="'heel', not a contact"):
        check_sequence(model, bad, swap)


def test_option_errors_name_the_formulation() -> None:
    legs = biped_of(load_model("five-link"))
    with pytest.raises(GaitOptionsError, match="formulation 'full' allows 0"):
        validate_options(GaitOptions.paper(min_stance_knee_flexion=0.0), legs)
    with pytest.raises(GaitOptionsError, match="formulation = 'polar': must be one of"):
        validate_options(GaitOptions.paper(formulation="polar"), legs)  # type: ignore[arg-type]
    with pytest.raises(GaitOptionsError, match=r"must lie in \[0, 1.5\)"):
        validate_options(FULL.replace(min_stance_knee_flexion=-0.1), legs)


def test_a_run_converges_and_is_physical(reference: RefFn, tmp_path) -> None:  # noqa: ANN001
    """Running is one more contact sequence (stance, flight): at 60 m/min it converges from
    its naive guess, is written as a gait file (format version 2, with its contact sequence)
    and read back; checked with Pinocchio at the knots (equations of motion, the stance tip
    at the origin, tip 2 landing one step ahead) and by verify; the feet are off the ground
    during the flight."""
    options = GaitOptions.paper(formulation="full", gait="run", impulse=False, speed=1.0,
                          single_support_fraction=0.5, min_stance_knee_flexion=0.0)
    gait = Gait.load(solve_gait("five-link", options).save(tmp_path / "run.gait.json"))
    assert gait.success and gait.version == 2
    assert gait.contact_sequence is not None and gait.contact_sequence["name"] == "run"
    assert [ph.name for ph in gait.phases] == ["stance", "flight"]
    assert [ph.contacts for ph in gait.phases] == [("tip_1",), ()]
    assert [e.name for e in gait.events] == ["toe_off", "touchdown"]
    assert_physics(reference(gait.model), gait)
    flight, nq = gait.phases[1], gait.model.nq
    ref = reference(gait.model)
    for k in range(1, flight.t.size - 1):
        for tip in ("tip_1", "tip_2"):
            height = ref.tip_kinematics(flight.q[k], flight.qd[k], np.zeros(nq), tip)[0][1]
            assert height > -1e-6
    landing = ref.tip_kinematics(flight.q[-1], flight.qd[-1], np.zeros(nq), "tip_2")[0]
    np.testing.assert_allclose(landing, [gait.step_length, 0.0], atol=1e-6)
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


def test_a_free_single_support_fraction(solved: SolveFn) -> None:
    """The fraction as a decision parameter within bounds: it converges, the gait file holds
    the solved fraction (phases, parameters and contact sequence agree), verify passes, and
    the cost is not above the fixed fraction's (which the free problem contains)."""
    fixed = solved(FULL).gait
    gait = solved(FULL.replace(single_support_fraction_bounds=(0.6, 0.95))).gait
    assert gait.success
    f = gait.parameters["single_support_time"] / gait.parameters["step_time"]
    assert 0.6 - 1e-6 <= f <= 0.95 + 1e-6
    assert gait.contact_sequence is not None
    assert gait.contact_sequence["phases"][0]["fraction"] == pytest.approx(f)
    assert gait.phases[0].duration / gait.step_time == pytest.approx(f)
    assert gait.cost_value <= fixed.cost_value * (1 + 1e-6)
    assert verify_gait(gait).passed


@pytest.mark.parametrize(("changes", "message"), [
    ({"single_support_fraction_bounds": (0.6, 0.95)}, "needs formulation 'full'"),
    ({"formulation": "full", "single_support_fraction_bounds": (0.6, 1.0)}, r"\[0.05, 1\)"),
    ({"formulation": "full", "single_support_fraction_bounds": (0.9, 0.95)},
     "sequence.single_support_fraction = 0.85: must lie in "
     "sequence.single_support_fraction_bounds"),
])
def test_free_fraction_errors(changes: dict[str, object], message: str) -> None:
    legs = biped_of(load_model("five-link"))
    with pytest.raises(GaitOptionsError, match=message):
        validate_options(GaitOptions.paper().replace(**changes), legs)
