"""Contact sequences as data: parsing, checks against a model, the heel-toe walk, the guess."""

from __future__ import annotations

import numpy as np
import pytest

from gaitopt.dynamics.kinematics import contact_position
from gaitopt.gait.formulations.full.physics import per_point, projection_names
from gaitopt.gait.formulations.select import checked_sequence, default_formulation
from gaitopt.gait.guess.sequence import contact_kinematics, sequence_guess
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError
from gaitopt.gait.sequence.builtin import (
    heel_toe_sequence,
    running_sequence,
    walking_sequence,
)
from gaitopt.gait.sequence.contact_sequence import (
    ContactSequenceError,
    check_sequence,
    sequence_from_dict,
)
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import leg_swap

PAPER = {
    "name": "my-walk",
    "phases": [{"name": "single_support", "held": ["tip_1"], "fraction": 0.75},
               {"name": "double_support", "held": ["tip_1", "tip_2"], "fraction": 0.25}],
    "events": [{"name": "heel_strike", "touchdown": ["tip_2"]},
               {"name": "liftoff", "release": ["tip_1"], "impulse": True}],
    "anchors": {"tip_1": 0.0, "tip_2": 1.0},
}




def swap(model: RobotModel) -> dict[str, str]:
    return dict(leg_swap(model).contacts)


def test_data_round_trip_equals_the_built_in_walk(five: RobotModel) -> None:
    seq = sequence_from_dict(PAPER)
    assert seq.phases == walking_sequence(five, 0.75, impulse=True).phases
    assert seq.events == walking_sequence(five, 0.75, impulse=True).events
    assert sequence_from_dict(seq.to_dict()) == seq
    check_sequence(five, seq, swap(five))


@pytest.mark.parametrize(("change", "message"), [
    (lambda d: d["phases"][1].update(held=["tip_1", "toe_2"]), "holds 'toe_2', not a contact"),
    (lambda d: d["phases"][0].update(fraction=0.5), "fractions sum to 0.75"),
    (lambda d: d["events"][0].update(touchdown=["tip_1"]), "touches down 'tip_1', which is held"),
    (lambda d: d["events"][1].update(release=[], impulse=False), "after event 'liftoff'"),
    (lambda d: d["anchors"].pop("tip_2"), "contact 'tip_2' has no anchor"),
    (lambda d: d["phases"][1].update(held=["tip_1", "tip_1:y"]), "holds a point twice"),
])
def test_bad_sequences_are_refused_by_name(five: RobotModel, change, message: str) -> None:
    import copy

    data = copy.deepcopy(PAPER)
    change(data)
    with pytest.raises(ContactSequenceError, match=message):
        check_sequence(five, sequence_from_dict(data), swap(five))


@pytest.mark.parametrize(("data", "message"), [
    ({"phases": [], "events": [], "anchors": {}}, r"phases = \[\]: must be a non-empty list"),
    ({**PAPER, "extra": 1}, r"unknown keys \['extra'\]"),
    ({**PAPER, "anchors": {"tip_1": "zero"}}, r"anchors.tip_1 = 'zero': must be a number"),
    ({**PAPER, "events": [{"name": "e", "impulse": "yes"}]}, "impulse = 'yes'"),
])
def test_malformed_data_names_the_field(data: dict, message: str) -> None:
    with pytest.raises(ContactSequenceError, match=message):
        sequence_from_dict(data)


def test_options_and_formulation_defaults(five: RobotModel, seven: RobotModel) -> None:
    assert default_formulation(five, "walk", False) == "reduced"
    assert default_formulation(five, "walk", True) == "full"
    assert default_formulation(seven, "walk", False) == "full"
    with pytest.raises(GaitOptionsError, match="need formulation 'full'"):
        from gaitopt.gait.options.gait_options import validate_options

        validate_options(GaitOptions(contact_sequence=PAPER), None)
    with pytest.raises(GaitOptionsError, match="two contact points on the foot"):
        checked_sequence(five, GaitOptions(formulation="full", gait="heel-toe"))


def test_heel_toe_sequence_of_the_seven_link_model(seven: RobotModel) -> None:
    seq = heel_toe_sequence(seven, swap(seven), 0.8, impulse=True)
    check_sequence(seven, seq, swap(seven))
    heel, toe = (np.asarray(contact_position(seven, np.zeros(seven.nq), c), dtype=float)
                 .ravel() for c in ("heel_1", "toe_1"))
    assert seq.ground_x("toe_1", 0.7) == pytest.approx(toe[0] - heel[0])
    assert seq.ground_x("heel_2", 0.7) == pytest.approx(0.7)
    assert [ph.held for ph in seq.phases] == [("heel_1", "toe_1:y"), ("toe_1",),
                                              ("toe_1", "heel_2"), ("heel_2",)]
    # The last event's impact holds what the next step's first phase holds, legs swapped.
    assert seq.holds_after(3, swap(seven)) == ("heel_2", "toe_2:y")
    assert projection_names(("heel_1", "toe_1:y")) == (
        "gamma_heel_1_x", "gamma_heel_1_y", "gamma_toe_1_y", "nu_heel_1_x", "nu_heel_1_y",
        "nu_toe_1_y")
    forces = per_point(("heel_1", "toe_1:y"), [1.0, 2.0, 3.0])
    assert {c: list(np.asarray(v, dtype=float).ravel()) for c, v in forces.items()} == {
        "heel_1": [1.0, 2.0], "toe_1": [0.0, 3.0]}


def test_the_guess_kinematics_are_the_model_kinematics(seven: RobotModel) -> None:
    # The inverse kinematics of the guess evaluates the contact points as one CasADi
    # function: the same expressions as the Python-float kinematics, so the same numbers.
    names = [c.name for c in seven.contacts]
    positions = contact_kinematics(seven, names)
    rng = np.random.default_rng(0)
    for _ in range(50):
        q = rng.uniform(-1.5, 1.5, seven.nq)
        got = np.asarray(positions(q)[0], dtype=float)
        for j, c in enumerate(names):
            want = np.asarray(contact_position(seven, q, c), dtype=float).ravel()
            np.testing.assert_allclose(got[:, j], want, rtol=1e-12, atol=1e-12)


def test_sequence_guess_puts_held_points_on_their_anchors(seven: RobotModel) -> None:
    seq = heel_toe_sequence(seven, swap(seven), 0.85, impulse=False)
    step = 0.5
    guess = sequence_guess(seven, seq, swap(seven), speed=0.5, step_length=step, knots=(8, 5),
                           ankle=True)
    assert [ph.name for ph in guess.phases] == [ph.name for ph in seq.phases]
    for ph, spec in zip(guess.phases, seq.phases, strict=True):
        for x in ph.x:
            q = x[:seven.nq]
            for hold in spec.held:
                name, _, axes = hold.partition(":")
                p = np.asarray(contact_position(seven, q, name), dtype=float).ravel()
                assert abs(p[1]) < 5e-3, (ph.name, name, p)
                if not axes:
                    assert abs(p[0] - seq.ground_x(name, step)) < 5e-3, (ph.name, name, p)
            for c in ("heel_1", "toe_1", "heel_2", "toe_2"):
                p = np.asarray(contact_position(seven, q, c), dtype=float).ravel()
                assert p[1] > -2e-3, (ph.name, c, p)


def test_the_inverse_kinematics_jacobian_is_the_residuals_derivative(seven: RobotModel) -> None:
    # The guess's least squares take the kinematics' own Jacobian: it must be the derivative
    # of the residual (central differences, points away from the ground's kink).
    from gaitopt.gait.guess.sequence import _PoseFit

    names = [c.name for c in seven.contacts]
    targets = {"heel_1": (0.0, 0.0, 10.0), "toe_1": (0.2, 0.0, 10.0),
               "heel_2": (None, 0.03, 1.0), "toe_2": (-0.3, 0.02, 1.0)}
    pose = np.zeros(seven.nq)
    fit = _PoseFit(contact_kinematics(seven, names), names, targets, (0.1, 0.9), pose, 1.1)
    rng = np.random.default_rng(1)
    for _ in range(10):
        q = np.concatenate([[0.0, 1.2, 0.0], rng.uniform(-0.5, 0.5, seven.nq - 3)])
        jac = fit.jacobian(q)
        h = 1e-6
        fd = np.column_stack([(fit.residual(q + h * e) - fit.residual(q - h * e)) / (2 * h)
                              for e in np.eye(seven.nq)])
        assert jac.shape == fd.shape
        np.testing.assert_allclose(jac, fd, atol=1e-7)


@pytest.mark.parametrize("speed, step", [(0.5, 0.45), (1.0, 0.666), (1.5, 0.75)])
def test_the_sequence_guess_moves_without_jumps(seven: RobotModel, speed: float,
                                                step: float) -> None:
    """The inverse kinematics follows one branch: neighbouring knots of a fine grid (a few
    ms apart) differ by little. The swing targets of a heel and a toe taken each on its own
    time off the ground asked for the toe 0.3 m behind the heel, and the poses jumped by
    2 rad between samples (accelerations of 1e5 rad/s^2 in the guess)."""
    seq = heel_toe_sequence(seven, swap(seven), 0.85, impulse=True)
    guess = sequence_guess(seven, seq, swap(seven), speed=speed, step_length=step,
                           knots=(60, 40), ankle=True)
    for ph in guess.phases:
        q = ph.x[:, :seven.nq]
        dt = np.diff(ph.t)
        assert dt.max() < 0.01
        jumps = np.abs(np.diff(q, axis=0)).max(axis=1)
        assert jumps.max() < 0.1, (ph.name, int(np.argmax(jumps)), jumps.max())


def test_a_flying_foots_targets_keep_its_length(seven: RobotModel) -> None:
    from gaitopt.gait.guess.sequence import _ground_points, _targets

    seq = heel_toe_sequence(seven, swap(seven), 0.85, impulse=True)
    step, total = 0.666, 0.666
    rows = _ground_points(seq, seq.period_contacts(swap(seven)), step, total)
    bodies = {c.name: tuple(o.name for o in seven.contacts if o.link == c.link)
              for c in seven.contacts}
    length = float(np.diff([seq.ground_x(c, step) for c in ("heel_1", "toe_1")])[0])
    flying = 0
    for t in np.linspace(0.0, total, 200):
        tg = _targets(rows, bodies, float(t), 0.05)
        for heel, toe in (("heel_1", "toe_1"), ("heel_2", "toe_2")):
            a, b = tg[heel], tg[toe]
            assert a is not None and b is not None
            if a[0] is not None and b[0] is not None and a[2] == b[2] == 1.0:
                flying += 1
                assert b[0] - a[0] == pytest.approx(length, abs=1e-12)
            assert a[1] is not None and 0.0 <= a[1] <= 0.05
    assert flying > 50


def test_phase_knots_keep_the_density_of_phase_0(five: RobotModel, seven: RobotModel) -> None:
    from gaitopt.gait.sequence.contact_sequence import phase_knots

    assert phase_knots(walking_sequence(five, 0.85, impulse=True), (8, 5)) == (8, 5)
    assert phase_knots(walking_sequence(five, 1.0, impulse=False), (8, 5)) == (8,)
    seq = heel_toe_sequence(seven, swap(seven), 0.85, impulse=True)
    # 15 intervals over 0.425 of the step: 35.3 per step; heel off 0.2975 -> 11 intervals,
    # double support 0.15 -> 6, heel rocker 0.1275 -> 5 (at least 6 knots everywhere).
    assert phase_knots(seq, (16, 6)) == (16, 12, 7, 6)


@pytest.mark.parametrize("stance", [0.95, 0.85, 0.6, 0.354, 0.2])
def test_a_runs_flight_is_not_coarser_than_its_stance(five: RobotModel, seven: RobotModel,
                                                      stance: float) -> None:
    """Two phases follow the density rule too: a long flight after a short stance gets the
    stance's knots per share of the step (the 400 m/min run's flight of 65 % had 6 knots on
    16 + 6, 5.5 times coarser than its stance, and failed ``integration.interval``)."""
    from gaitopt.gait.sequence.contact_sequence import phase_knots

    for model in (five, seven):
        for knots in ((16, 6), (8, 5), (24, 8)):
            first, flight = phase_knots(running_sequence(model, stance), knots)
            assert first == knots[0]
            assert flight >= knots[1]
            density = (first - 1) / stance  # intervals per share of the step
            assert (flight - 1) / (1 - stance) >= density - 1e-9  # not coarser
            # and the fewest knots that are not: one interval less would be coarser
            assert flight == knots[1] or (flight - 2) / (1 - stance) < density
