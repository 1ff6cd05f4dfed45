"""Strides (``GaitOptions.stride``, ``--stride``): two steps periodic over two step lengths
with no leg swap assumed. On the symmetric five-link biped the stride is two mirrored copies
of the one-step optimum (the same cost); with one heavier shank its two steps differ. The
stride's contact sequence, its gait file and its checks."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.analysis.checks.events import period_maps
from gaitopt.analysis.stability import StabilityError, step_from_gait
from gaitopt.analysis.verify import verify_gait
from gaitopt.cli import cli
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.builtin import heel_toe_sequence, walking_sequence
from gaitopt.gait.sequence.contact_sequence import (
    check_sequence,
    phase_knots,
    sequence_from_dict,
    stride_sequence,
)
from gaitopt.robot import RobotModel, load_model, model_from_dict
from gaitopt.robot.symmetry import contact_pairing, swap_matrices
from tests.gait.conftest import SolveFn, recomputed_cost

#: Full coordinates on the one grid 16 + 6 per step (knots given: no refinement, so the step
#: and the stride are compared on like grids).
FULL = GaitOptions(formulation="full", knots=(16, 6))
TIPS = {"tip_1": "tip_2", "tip_2": "tip_1"}


def _heavy_shank() -> RobotModel:
    """The five-link biped with shank 2 20 % heavier (4.8 kg, its shape's inertia)."""
    data = copy.deepcopy(load_model("five-link").to_dict())
    data["name"] = "five-link-heavy-shank-2"
    shank = next(link for link in data["links"] if link["name"] == "shank_2")
    shank["mass"] = 1.2 * shank["mass"]
    del shank["inertia"]  # from its shape, with the new mass
    return model_from_dict(data)


def _mirror_errors(gait: Gait) -> tuple[float, float]:
    """Largest difference of the stride's second step from its first mirrored (``S_q q``
    shifted one step length, ``S_u u``) at the same knots: (states, controls)."""
    s_q, s_u = swap_matrices(gait.model)
    half = len(gait.phases) // 2
    state = control = 0.0
    for first, second in zip(gait.phases[:half], gait.phases[half:], strict=True):
        np.testing.assert_allclose(second.t, first.t + gait.step_time, atol=1e-9)
        q = first.q @ s_q.T
        q[:, 0] += gait.step_length
        state = max(state, float(np.abs(q - second.q).max()),
                    float(np.abs(first.qd @ s_q.T - second.qd).max()))
        control = max(control, float(np.abs(first.u @ s_u.T - second.u).max()))
    return state, control


def test_the_stride_sequence_is_the_step_twice_with_the_legs_renamed() -> None:
    model = load_model("five-link")
    stride = stride_sequence(walking_sequence(model, 0.85, impulse=True), TIPS)
    assert stride.steps == 2
    assert [ph.name for ph in stride.phases] == ["single_support", "double_support",
                                                 "single_support_2", "double_support_2"]
    assert [ph.held for ph in stride.phases] == [("tip_1",), ("tip_1", "tip_2"), ("tip_2",),
                                                 ("tip_2", "tip_1")]
    assert [ph.fraction for ph in stride.phases] == pytest.approx([0.425, 0.075] * 2)
    assert [ev.touchdown + ev.release for ev in stride.events] == [
        ("tip_2",), ("tip_1",), ("tip_1",), ("tip_2",)]
    # Tip 1 stands at 0 in the first step and lands two step lengths ahead in the second.
    assert [stride.ground_x("tip_1", 0.5, i) for i in (0, 3)] == [0.0, 1.0]
    assert [stride.ground_x("tip_2", 0.5, i) for i in (1, 2)] == [0.5, 0.5]
    check_sequence(model, stride, TIPS)  # the last event leads into phase 0 without swap
    assert sequence_from_dict(stride.to_dict()) == stride
    assert "steps" not in walking_sequence(model, 0.85, impulse=True).to_dict()


def test_each_step_of_a_stride_gets_the_knots_of_one_step() -> None:
    model = load_model("five-link")
    for f in (0.85, 1.0):
        step = walking_sequence(model, f, impulse=f < 1.0)
        assert phase_knots(stride_sequence(step, TIPS), (16, 6)) == 2 * phase_knots(
            step, (16, 6))
    heel_toe = heel_toe_sequence(load_model("seven-link"), contact_pairing(
        load_model("seven-link")), 0.8, impulse=True)
    stride = stride_sequence(heel_toe, contact_pairing(load_model("seven-link")))
    assert phase_knots(stride, (24, 16)) == 2 * phase_knots(heel_toe, (24, 16))


def test_a_heel_toe_stride_renames_the_feet_and_keeps_their_offsets() -> None:
    model = load_model("seven-link")
    pairing = contact_pairing(model)
    stride = stride_sequence(heel_toe_sequence(model, pairing, 0.8, impulse=True), pairing)
    check_sequence(model, stride, pairing)
    toe_off = stride.offset("toe_1")
    assert toe_off > 0.0 and stride.offset("toe_2", 5) == toe_off
    assert stride.ground_x("heel_2", 1.0, 5) == 1.0 and stride.ground_x("heel_1", 1.0, 6) == 2.0


def test_a_stride_needs_the_full_formulation() -> None:
    model = load_model("five-link")
    with pytest.raises(GaitOptionsError, match="stride: a two-step stride needs formulation "
                                               "'full'"):
        validate_options(GaitOptions(stride=True), None)
    with pytest.raises(GaitOptionsError,
                       match="sequence.stride and sequence.single_support_fraction_bounds"):
        validate_options(FULL.replace(stride=True,
                                      single_support_fraction_bounds=(0.7, 0.9)), None)
    result = CliRunner().invoke(cli, ["solve", "--stride", "--formulation", "reduced",
                                      "-o", "/dev/null"])
    assert result.exit_code != 0 and "needs formulation 'full'" in result.output
    validate_options(FULL.replace(stride=True), None)
    assert model.nq == 7


def test_the_stride_of_the_five_link_is_two_mirrored_optimal_steps(solved: SolveFn) -> None:
    """12 m/min, 16 + 6 knots per step in both (like with like): the stride's cost per metre
    is the one-step optimum's within 10 x the solver's tolerance, and its second step is its
    first mirrored by the leg swap; verify checks the stride's periodicity (no swap, x + 2 L)
    and passes; the file records the stride."""
    step = solved(FULL).gait
    stride = solved(FULL.replace(stride=True)).gait
    assert step.success and stride.success
    assert stride.cost_value == pytest.approx(step.cost_value, rel=10 * FULL.tol)
    assert stride.step_length == pytest.approx(step.step_length, rel=1e-4)
    state, control = _mirror_errors(stride)
    assert state < 1e-5 and control < 1e-4
    assert stride.period_steps == 2 and stride.options["stride"] is True
    assert stride.contact_sequence is not None and stride.contact_sequence["steps"] == 2
    s_q, _, names = period_maps(stride)
    np.testing.assert_array_equal(s_q, np.eye(7))
    assert names == {}
    assert recomputed_cost(stride) == pytest.approx(stride.cost_value, rel=1e-6)
    report = verify_gait(stride)
    assert report.passed, report.failed_ids
    reloaded = Gait.from_dict(stride.to_dict())
    assert reloaded.period_steps == 2
    samples = stride.stride_samples(4)  # two strides, never swapped
    assert samples.t[-1] == pytest.approx(4 * stride.step_time)
    with pytest.raises(StabilityError, match="stride"):
        step_from_gait(stride)


def test_the_single_support_stride_is_the_one_step_optimum(solved: SolveFn) -> None:
    """The single-support walk (one phase per step, 16 knots each): the same cost within
    10 x the solver's tolerance, the steps mirrored."""
    options = FULL.replace(single_support_fraction=1.0)
    step = solved(options).gait
    stride = solved(options.replace(stride=True)).gait
    assert step.success and stride.success
    assert stride.cost_value == pytest.approx(step.cost_value, rel=10 * FULL.tol)
    state, control = _mirror_errors(stride)
    assert state < 1e-5 and control < 1e-4


def test_a_heavier_shank_walks_with_two_different_steps(solved: SolveFn) -> None:
    """Shank 2 20 % heavier: the stride solves and passes verify, and its second step is no
    mirror of its first (states by more than 1e-3, torques by more than 0.1 N m)."""
    gait = solved(FULL.replace(stride=True), _heavy_shank()).gait
    assert gait.success
    report = verify_gait(gait)
    assert report.passed, report.failed_ids
    state, control = _mirror_errors(gait)
    assert state > 1e-3 and control > 0.1
