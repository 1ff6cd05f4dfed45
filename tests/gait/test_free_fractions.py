"""Free phase fractions for any contact sequence: the data form, the parameters and their
remainder, the checks, and solves (the same optimum as the two-phase
``single_support_fraction_bounds``; the solved fractions in the gait file; a heel-toe walk of
the seven-link model with every share free, slow)."""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.api import solve_gait
from gaitopt.gait.formulations.select import checked_sequence, contact_sequence, problem_for
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.builtin import heel_toe_sequence, walking_sequence
from gaitopt.gait.sequence.contact_sequence import (
    ContactSequenceError,
    check_sequence,
    sequence_from_dict,
)
from gaitopt.gait.sequence.phase_fractions import (
    FRACTION_PARAMETER,
    fraction_parameters,
    phase_share,
    remainder_bounds,
    with_first_fraction_bounds,
    with_free_fractions,
)
from gaitopt.robot.loader import load_model
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import leg_swap
from tests.gait.conftest import Solved

SolveFn = Callable[..., Solved]

FULL = GaitOptions.paper(formulation="full")

#: The paper's walk with both fractions free, the bounds of ``single_support_fraction_bounds
#: = (0.6, 0.95)`` written out (double support ``1 - f``).
FREE_WALK: dict[str, Any] = {
    "name": "walk-free",
    "phases": [{"name": "single_support", "held": ["tip_1"],
                "fraction": {"guess": 0.85, "min": 0.6, "max": 0.95}},
               {"name": "double_support", "held": ["tip_1", "tip_2"],
                "fraction": {"guess": 0.15, "min": 0.05, "max": 0.4}}],
    "events": [{"name": "heel_strike", "touchdown": ["tip_2"]},
               {"name": "liftoff", "release": ["tip_1"], "impulse": True}],
    "anchors": {"tip_1": 0.0, "tip_2": 1.0},
}




def _swap(model: RobotModel) -> dict[str, str]:
    return dict(leg_swap(model).contacts)


# -- the data form ------------------------------------------------------------------------------

def test_a_fraction_with_bounds_reads_and_writes_back(five: RobotModel) -> None:
    seq = sequence_from_dict(FREE_WALK)
    assert [ph.fraction for ph in seq.phases] == [0.85, 0.15]
    assert [ph.bounds for ph in seq.phases] == [(0.6, 0.95), (0.05, 0.4)]
    assert seq.to_dict()["phases"][0]["fraction"] == {"guess": 0.85, "min": 0.6, "max": 0.95}
    assert sequence_from_dict(seq.to_dict()) == seq
    check_sequence(five, seq, _swap(five))


def _with_fraction(k: int, value: Any) -> dict[str, Any]:
    data = copy.deepcopy(FREE_WALK)
    data["phases"][k]["fraction"] = value
    return data


@pytest.mark.parametrize(("value", "message"), [
    ({"guess": 0.85, "min": 0.9, "max": 0.95}, r"phases\[0\].fraction = .*0 < min <= guess"),
    ({"guess": 0.85, "min": 0.0, "max": 0.95}, r"0 < min <= guess <= max <= 1"),
    ({"guess": 0.85, "min": 0.6, "max": 1.2}, r"0 < min <= guess <= max <= 1"),
    ({"guess": 0.85, "min": 0.6}, r"phases\[0\].fraction = .*missing max"),
    ({"guess": 0.85, "min": 0.6, "max": 0.9, "step": 1}, r"unknown keys \['step'\]"),
    ({"guess": "a", "min": 0.6, "max": 0.9}, r"phases\[0\].fraction.guess = 'a': must be a num"),
])
def test_bad_fraction_bounds_name_the_field(value: Any, message: str) -> None:
    with pytest.raises(ContactSequenceError, match=message):
        sequence_from_dict(_with_fraction(0, value))


def test_a_single_free_phase_is_refused(five: RobotModel) -> None:
    """With every other share fixed, one free share has nothing to trade with."""
    seq = sequence_from_dict(_with_fraction(1, 0.15))
    with pytest.raises(ContactSequenceError, match="'single_support' is the only one"):
        check_sequence(five, seq, _swap(five))


def test_first_guesses_must_sum_to_one(five: RobotModel) -> None:
    seq = sequence_from_dict(_with_fraction(1, {"guess": 0.2, "min": 0.05, "max": 0.4}))
    with pytest.raises(ContactSequenceError, match=r"fractions \(first guesses\) sum to 1.05"):
        check_sequence(five, seq, _swap(five))


# -- the parameters and the remainder -----------------------------------------------------------

def test_the_last_free_phase_takes_the_remainder(seven: RobotModel) -> None:
    """Heel-toe with every share free: one parameter per phase but the last, and for any
    parameter values the four shares sum to 1 (an identity, not a constraint)."""
    seq = with_free_fractions(heel_toe_sequence(seven, _swap(seven), 0.85, impulse=True))
    params = fraction_parameters(seq)
    assert [fp.name for fp in params] == [FRACTION_PARAMETER + ph.name for ph in seq.phases[:3]]
    assert [fp.guess for fp in params] == [ph.fraction for ph in seq.phases[:3]]
    rng = np.random.default_rng(3)
    for _ in range(5):
        values = rng.uniform(0.05, 0.4, size=3)
        shares = [phase_share(seq, i, list(values)) for i in range(4)]
        assert shares[:3] == list(values)
        assert sum(shares) == pytest.approx(1.0, abs=1e-12)
    guesses = [phase_share(seq, i, [fp.guess for fp in params]) for i in range(4)]
    np.testing.assert_allclose(guesses, [ph.fraction for ph in seq.phases], atol=1e-12)


def test_default_bounds_halve_or_double_each_share(five: RobotModel) -> None:
    seq = with_free_fractions(walking_sequence(five, 0.85, impulse=True))
    assert seq.phases[0].bounds == pytest.approx((0.425, 0.95))
    assert seq.phases[1].bounds == pytest.approx((0.075, 0.3))
    one = walking_sequence(five, 1.0, impulse=False)
    assert with_free_fractions(one) == one  # the single-support walk: nothing to free


def test_a_remainder_row_only_where_the_other_bounds_do_not_imply_it(five: RobotModel) -> None:
    """Two phases with ``f`` in [lo, hi] imply the remainder's [1 - hi, 1 - lo]: no row (it
    would repeat an active bound); the default bounds do not imply the double support's."""
    walk = walking_sequence(five, 0.85, impulse=True)
    assert remainder_bounds(with_first_fraction_bounds(walk, (0.6, 0.95))) is None
    assert remainder_bounds(sequence_from_dict(FREE_WALK)) is None
    assert remainder_bounds(with_free_fractions(walk)) == (1, pytest.approx(0.075),
                                                           pytest.approx(0.3))
    assert remainder_bounds(walk) is None


def test_the_problem_has_a_parameter_per_free_fraction_and_durations_sum_to_the_step(
        seven: RobotModel) -> None:
    options = GaitOptions(formulation="full", gait="heel-toe", free_phase_fractions=True)
    seq = contact_sequence(seven, options)
    problem = problem_for(seven, options)
    names = [p.name for p in problem.parameters]
    params = fraction_parameters(seq)
    assert names == ["step_length", "speed", "impulse"] + [fp.name for fp in params]
    for par, fp in zip(problem.parameters[3:], params, strict=True):
        assert (par.lower, par.upper, par.guess) == (fp.lower, fp.upper, fp.guess)
    step, speed = 0.7, 0.5
    p = np.array([step, speed, 0.0, 0.3, 0.1, 0.2])
    durations = [ph.duration.expression(p) for ph in problem.phases]  # type: ignore[misc]
    assert sum(durations) == pytest.approx(step / speed, rel=1e-12)
    assert durations[:3] == pytest.approx([0.3 * step / speed, 0.1 * step / speed,
                                           0.2 * step / speed])
    assert any(c.name.startswith("heel_rocker: share within its bounds")
               for c in problem.boundary_constraints)


@pytest.mark.parametrize(("changes", "message"), [
    ({"free_phase_fractions": True}, "free_phase_fractions: free phase fractions need "
                                     "formulation 'full'"),
    ({"formulation": "full", "free_phase_fractions": True,
      "single_support_fraction_bounds": (0.6, 0.95)}, "give one of them"),
])
def test_option_errors(five: RobotModel, changes: dict[str, Any], message: str) -> None:
    with pytest.raises(GaitOptionsError, match=message):
        validate_options(GaitOptions(**changes), None)


@pytest.mark.parametrize(("options", "message"), [
    (GaitOptions(formulation="full", free_phase_fractions=True, single_support_fraction=1.0,
                 impulse=False), "has one phase"),
    (GaitOptions(formulation="full", gait="heel-toe", single_support_fraction_bounds=(0.6, 0.9)),
     "needs a sequence of two phases; it has 4"),
])
def test_sequence_errors(seven: RobotModel, five: RobotModel, options: GaitOptions,
                         message: str) -> None:
    model = seven if options.gait == "heel-toe" else five
    with pytest.raises(GaitOptionsError, match=message):
        checked_sequence(model, options)


# -- solves -------------------------------------------------------------------------------------

def test_both_mechanisms_give_the_same_optimum(solved: SolveFn) -> None:
    """Five-link walk at 12 m/min in full coordinates: the single-support fraction free in
    [0.6, 0.95] by ``single_support_fraction_bounds`` (from the two-link guess) and by a
    sequence whose two fractions carry the same bounds (from the generic guess): the same
    optimum to 1e-5, 10 x the solves' accuracy (cost, step length and fractions)."""
    old = solved(FULL.replace(single_support_fraction_bounds=(0.6, 0.95))).gait
    new = solved(FULL.replace(contact_sequence=FREE_WALK)).gait
    assert old.success and new.success
    assert new.cost_value == pytest.approx(old.cost_value, rel=1e-5)
    assert new.step_length == pytest.approx(old.step_length, rel=1e-5)
    assert old.contact_sequence is not None and new.contact_sequence is not None
    for a, b in zip(old.contact_sequence["phases"], new.contact_sequence["phases"],
                    strict=True):
        assert b["fraction"] == pytest.approx(a["fraction"], abs=1e-6)


def test_every_free_fraction_reaches_the_gait_file(solved: SolveFn, tmp_path: Any) -> None:
    """``free_phase_fractions`` on the paper's walk: the file (read back) holds the solved
    shares as plain numbers, within their bounds, summing to 1 and equal to the phase
    durations over the step time; the cost is not above the fixed shares' (the free problem
    contains it); verify passes."""
    fixed = solved(FULL).gait
    gait = Gait.load(solved(FULL.replace(free_phase_fractions=True)).gait.save(
        tmp_path / "free.gait.json"))
    assert gait.success
    assert gait.contact_sequence is not None
    shares = [float(ph["fraction"]) for ph in gait.contact_sequence["phases"]]
    assert sum(shares) == pytest.approx(1.0, abs=1e-9)
    bounds = [(0.425, 0.95), (0.075, 0.3)]
    for share, (lo, hi), ph in zip(shares, bounds, gait.phases, strict=True):
        assert lo - 1e-6 <= share <= hi + 1e-6
        assert ph.duration / gait.step_time == pytest.approx(share, rel=1e-9)
    assert gait.cost_value <= fixed.cost_value * (1 + 1e-6)
    assert gait.options["free_phase_fractions"] is True
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


@pytest.mark.slow
def test_a_free_fraction_optimum_is_the_fixed_optimum_at_its_shares(solved: SolveFn) -> None:
    """The run (stance then flight) at 60 m/min with both shares free in [0.3, 0.7]: a fixed
    solve at the solved stance share, on the free solve's knots and started from its
    optimum, stays at its cost (the free optimum is an optimum of the problem it contains),
    and the shares sum to 1. (The knots follow the shares since a1a8151: at the stance share
    0.7 the fixed run gets 8 + 5 knots where the free one, whose shares start at 0.5, has
    8 + 8, and on 8 + 5 it costs 3430.65 against the free 3263.16.)"""
    base = GaitOptions.paper(formulation="full", gait="run", impulse=False, speed=1.0,
                             single_support_fraction=0.5, step_length_bounds=(0.2, 1.5))
    free = solved(base.replace(single_support_fraction_bounds=(0.3, 0.7))).gait
    assert free.success and free.contact_sequence is not None
    f = float(free.contact_sequence["phases"][0]["fraction"])
    knots = {ph.name: ph.t.size for ph in free.phases}
    fixed = solve_gait("five-link", base.replace(single_support_fraction=f, knots=knots),
                       warm_start=free)
    assert fixed.success
    assert fixed.cost_value == pytest.approx(free.cost_value, rel=1e-5)
    assert free.cost_value <= solved(base).gait.cost_value * (1 + 1e-6)


@pytest.mark.slow
def test_heel_toe_with_every_share_free_converges_and_verifies() -> None:
    """Seven-link heel-toe walk, 24+16 knots, 30 m/min, all four shares free: converges,
    verify passes, the shares sum to 1 within their bounds, and the cost is not above the
    walk with the fixed shares."""
    options = GaitOptions(formulation="full", gait="heel-toe", knots=(24, 16), speed=0.5,
                          free_phase_fractions=True)
    gait = solve_gait("seven-link", options)
    assert gait.success
    report = verify_gait(gait)
    assert report.passed, report.failed_ids
    assert gait.contact_sequence is not None
    shares = [float(ph["fraction"]) for ph in gait.contact_sequence["phases"]]
    assert sum(shares) == pytest.approx(1.0, abs=1e-9)
    seq = contact_sequence(load_model("seven-link"), options)
    for share, ph in zip(shares, seq.phases, strict=True):
        assert ph.bounds is not None
        assert ph.bounds[0] - 1e-6 <= share <= ph.bounds[1] + 1e-6
    fixed = solve_gait("seven-link", options.replace(free_phase_fractions=False))
    assert fixed.success
    assert gait.cost_value <= fixed.cost_value * (1 + 1e-6)


# -- the command line ---------------------------------------------------------------------------

def _solve_cli(*args: str) -> Any:
    from click.testing import CliRunner

    from gaitopt.cli import cli

    return CliRunner().invoke(cli, ["solve", *args])


@pytest.mark.parametrize(("args", "words"), [
    (["--free-fractions"], ("free_phase_fractions", "formulation 'full'")),
    (["--free-fractions", "--formulation", "full", "--single-support-bounds", "0.6,0.9"],
     ("give one of them",)),
    (["--free-fractions", "--formulation", "full", "--single-support", "1", "--no-impulse"],
     ("free_phase_fractions", "has one phase")),
])
def test_bad_free_fraction_requests_exit_2_with_one_line(tmp_path: Any, args: list[str],
                                                         words: tuple[str, ...]) -> None:
    out = tmp_path / "g.gait.json"
    result = _solve_cli(*args, "-o", str(out))
    assert result.exit_code == 2, (result.output, result.exception)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    for word in words:
        assert word in lines[0], lines[0]
    assert not out.exists()


def test_a_bad_fraction_in_a_sequence_file_exits_2_naming_it(tmp_path: Any) -> None:
    file = tmp_path / "seq.yaml"
    file.write_text(
        "phases:\n"
        "  - {name: a, held: [tip_1], fraction: {guess: 0.8, min: 0.9, max: 0.95}}\n"
        "  - {name: b, held: [tip_1, tip_2], fraction: 0.2}\n"
        "events: [{name: s, touchdown: [tip_2]}, {name: l, release: [tip_1]}]\n"
        "anchors: {tip_1: 0, tip_2: 1}\n")
    result = _solve_cli("--contact-sequence", str(file), "-o", str(tmp_path / "g.gait.json"))
    assert result.exit_code == 2, (result.output, result.exception)
    assert "phases[0].fraction" in result.stderr and "0 < min <= guess" in result.stderr


def test_the_summary_prints_the_solved_fractions(tmp_path: Any, solved: SolveFn) -> None:
    """``--free-fractions`` on the paper's grid: the same optimum as the API's, and the
    summary names each phase's solved share and that it was free."""
    api = solved(FULL.replace(free_phase_fractions=True)).gait
    out = tmp_path / "free.gait.json"
    result = _solve_cli("--formulation", "full", "--paper-grid", "--free-fractions", "-o",
                        str(out))
    assert result.exit_code == 0, result.output
    gait = Gait.load(out)
    assert gait.cost_value == pytest.approx(api.cost_value, rel=1e-5)
    assert gait.contact_sequence is not None
    shares = [ph["fraction"] for ph in gait.contact_sequence["phases"]]
    # the table may wrap a cell onto the next line: compare its words without the rules
    text = " ".join(result.output.replace("│", " ").split())
    assert (f"phase fractions single_support {shares[0]:.4f} (free), double_support "
            f"{shares[1]:.4f} (free)") in text
