"""Defaults that follow the model (issue 24, item 4): the gait the feet allow, bounds,
guesses and NLP scales carried over by Froude scaling, the five-link values unchanged to the
bit, and the pre-flight checks that stop a model that cannot walk before any solve."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.api import solve_gait
from gaitopt.gait.formulations import cost
from gaitopt.gait.guess.naive import default_running_step, default_step_length
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, follows_model
from gaitopt.gait.options.model_defaults import (
    DEFAULT_SPEEDS,
    MULTI_PHASE_KNOTS,
    default_gait,
    default_speed,
    gait_problem,
    legs_contacts,
    options_for_model,
)
from gaitopt.gait.options.model_scale import REFERENCE, leg_length, model_scale
from gaitopt.gait.options.preflight import UnwalkableModelError, preflight
from gaitopt.gait.solve.staged import REFERENCE_SPEED, reference_speed
from gaitopt.robot import load_model
from tests.gait.conftest import SolveFn

DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).resolve().parents[2]
#: The scaled copy of the five-link biped: lengths x0.5, masses x0.2.
HALF, LENGTH, MASS = DATA / "five-link-half.yaml", 0.5, 0.2


# -- the gait the feet allow ---------------------------------------------------------------------

@pytest.mark.parametrize(("model", "gait"), [
    ("five-link", "walk"), ("adult-point-feet", "walk"), ("seven-link", "heel-toe"),
    (str(HALF), "walk")])
def test_the_default_gait_is_what_the_contact_points_per_leg_allow(model: str,
                                                                   gait: str) -> None:
    robot = load_model(model)
    assert default_gait(robot) == gait
    resolved = options_for_model(robot, GaitOptions())
    assert resolved.gait == gait and not follows_model(resolved.gait)
    assert resolved.formulation == ("full" if gait == "heel-toe" else "reduced")
    assert resolved.knots == (MULTI_PHASE_KNOTS if gait == "heel-toe" else (16, 6))


def test_the_legs_group_the_contact_points_by_the_link_below_the_base() -> None:
    assert legs_contacts(load_model("seven-link")) == (("heel_1", "toe_1"), ("heel_2", "toe_2"))
    assert legs_contacts(load_model("five-link")) == (("tip_1",), ("tip_2",))


def test_a_gait_the_model_cannot_do_is_refused_naming_the_one_it_can() -> None:
    seven, five = load_model("seven-link"), load_model("five-link")
    why = gait_problem(seven, "walk")
    assert why is not None and "heel and a toe on each foot" in why and "--gait heel-toe" in why
    why = gait_problem(five, "heel-toe")
    assert why is not None and "one contact point on each leg" in why and "'walk'" in why
    assert gait_problem(five, "run") is None and gait_problem(seven, "heel-toe") is None
    with pytest.raises(GaitOptionsError, match="heel-toe"):
        options_for_model(seven, GaitOptions(gait="walk"))
    # A given contact sequence replaces the gait: no gait check.
    sequence = {"phases": [{"name": "a", "held": ["heel_1"], "fraction": 1.0}],
                "events": [{"name": "e", "touchdown": ["heel_2"], "release": ["heel_1"]}],
                "anchors": {"heel_1": 0.0, "heel_2": 1.0}}
    custom = options_for_model(seven, GaitOptions(contact_sequence=sequence))
    assert custom.formulation == "full" and custom.knots == (16, 6)


def test_a_given_option_is_kept_and_a_default_follows_the_model() -> None:
    seven = load_model("seven-link")
    given = options_for_model(seven, GaitOptions(speed=0.5, knots=(16, 10),
                                                 step_length_bounds=(0.1, 0.9)))
    assert (given.speed, given.knots, given.step_length_bounds) == (0.5, (16, 10), (0.1, 0.9))
    assert given.speed_bounds != GaitOptions().speed_bounds  # not given: the model's
    free = options_for_model(seven, GaitOptions(speed=None))
    assert free.speed is None


# -- the five-link values, unchanged to the bit ----------------------------------------------

def test_the_five_link_defaults_are_exactly_the_reference_values() -> None:
    five = load_model("five-link")
    scale = model_scale(five)
    assert (scale.leg_length, scale.mass, scale.gravity) == (1.0, 42.0, 9.81)
    assert scale == REFERENCE
    assert (scale.length_factor, scale.speed_factor, scale.time_factor,
            scale.force_factor) == (1.0, 1.0, 1.0, 1.0)
    resolved = options_for_model(five, GaitOptions())
    expected = {"speed": 0.2, "speed_bounds": (0.02, 1.5), "step_length_bounds": (0.02, 0.8),
                "rate_bound": 15.0, "max_impulse": 30.0, "cost_smoothing": 0.01,
                "knots": (16, 6), "gait": "walk", "formulation": "reduced"}
    for name, value in expected.items():
        got = getattr(resolved, name)
        assert got == value and type(got) is type(value), name
        assert not follows_model(got)
    assert resolved == GaitOptions() and resolved.to_dict() == GaitOptions().to_dict()
    assert default_speed(five, "walk") == REFERENCE_SPEED == 0.2
    assert reference_speed(five, resolved) == 0.2
    for v in (0.02, 0.2, 0.5, 1.0, 1.5):
        assert default_step_length(v, scale) == float(min(max(0.06 + 0.35 * v, 0.05), 0.5))
        assert default_running_step(v, scale) == default_running_step(v)
    assert cost.objective_scale(resolved, scale) == 1000.0


# -- the scaled five-link --------------------------------------------------------------------

def test_the_scaled_models_bounds_and_guesses_scale_with_its_legs_and_mass() -> None:
    """Lengths x0.5, masses x0.2: speeds x sqrt(0.5), lengths x0.5, rates / sqrt(0.5),
    impulses x 0.2 sqrt(0.5), the paper cost x 0.2^2 0.5^1.5."""
    half = load_model(HALF)
    scale = model_scale(half)
    assert scale.leg_length == pytest.approx(LENGTH, rel=1e-15)
    assert scale.mass == pytest.approx(42.0 * MASS, rel=1e-15)
    o = options_for_model(half, GaitOptions())
    root = math.sqrt(LENGTH)
    assert o.speed == pytest.approx(0.2 * root, rel=1e-14)
    assert o.speed_bounds == pytest.approx((0.02 * root, 1.5 * root), rel=1e-14)
    assert o.step_length_bounds == pytest.approx((0.01, 0.4), rel=1e-14)
    assert o.rate_bound == pytest.approx(15.0 / root, rel=1e-14)
    assert o.max_impulse == pytest.approx(30.0 * MASS * root, rel=1e-14)
    assert cost.objective_scale(o, scale) == pytest.approx(1000.0 * MASS**2 * LENGTH**1.5,
                                                           rel=1e-14)
    v = 0.2 * root  # the same Froude number as 0.2 m/s on 1 m legs: half the step
    assert default_step_length(v, scale) == pytest.approx(LENGTH * default_step_length(0.2),
                                                          rel=1e-14)


def test_the_scaled_five_link_walks_the_five_links_optimum_in_dimensionless_units(
        solved: SolveFn) -> None:
    """Dynamically similar models at equal Froude number: the scaled model's default walk is
    the five-link's, its cost times m^2 g^1.5 l^1.5 (0.2^2 0.5^1.5), its step times 0.5."""
    five = solved(GaitOptions()).gait
    half = solve_gait(load_model(HALF), GaitOptions())
    assert five.success and half.success
    factor = MASS**2 * LENGTH**1.5
    assert half.cost_value / factor == pytest.approx(five.cost_value, rel=1e-5)
    assert half.step_length / LENGTH == pytest.approx(five.step_length, rel=1e-5)
    assert half.speed == pytest.approx(0.2 * math.sqrt(LENGTH), rel=1e-12)


def test_seven_link_default_speed_is_the_heel_toe_walks_at_equal_froude_number() -> None:
    seven = load_model("seven-link")
    assert leg_length(seven) == pytest.approx(0.9275, rel=1e-12)
    v = default_speed(seven, "heel-toe")
    assert v == pytest.approx(DEFAULT_SPEEDS["heel-toe"] * math.sqrt(0.9275), rel=1e-12)
    assert 70.0 < v * 60.0 < 75.0  # 72.2 m/min: where the default grid is converged
    assert v / math.sqrt(9.81 * 0.9275) == pytest.approx(1.25 / math.sqrt(9.81), rel=1e-12)


# -- pre-flight -------------------------------------------------------------------------------

UNWALKABLE = {
    "five-link-backward-hips.yaml": ("can never be in front of", "hip_1 [-2, -0.9]",
                                     "widen the hip range forward"),
    "five-link-passive-hips.yaml": ("joint 'hip_1'", "has no actuator",
                                    "add one to the model's actuators"),
    "five-link-legs-up.yaml": ("cannot reach the ground", "hip_1 [2.8, 3.2]",
                               "widen the ranges"),
}


@pytest.mark.parametrize("model", ["five-link", "seven-link", "adult-point-feet", str(HALF)])
def test_the_walking_models_pass_preflight(model: str) -> None:
    robot = load_model(model)
    assert preflight(robot, options_for_model(robot, GaitOptions())) == ()


@pytest.mark.parametrize("file", list(UNWALKABLE))
def test_a_model_that_cannot_walk_is_named_by_preflight(file: str) -> None:
    robot = load_model(DATA / file)
    problems = preflight(robot, GaitOptions())
    assert problems
    for word in UNWALKABLE[file]:
        assert word in problems[0], problems[0]
    with pytest.raises(UnwalkableModelError, match=UNWALKABLE[file][0]):
        solve_gait(robot, GaitOptions())


def test_the_torso_bounds_decide_whether_backward_hips_can_step() -> None:
    """Hips in [-2, 0] (thighs behind the torso axis) can still put one leg in front of the
    other by leaning the torso back, within +-0.8 rad; not within +-0.02 rad."""
    from gaitopt.robot.loader import parse_yaml
    from gaitopt.robot.schema import model_from_dict

    text = (DATA / "five-link-backward-hips.yaml").read_text().replace("-0.9]", "0.0]")
    robot = model_from_dict(parse_yaml(text))
    assert preflight(robot, GaitOptions()) == ()
    leaning = preflight(robot, GaitOptions(torso_bounds=(-0.02, 0.02)))
    assert leaning and "can never be in front of" in leaning[0]


@pytest.mark.parametrize("file", list(UNWALKABLE))
def test_solve_refuses_a_model_that_cannot_walk_in_one_line(tmp_path: Path,
                                                            file: str) -> None:
    """The installed entry point: one line on stderr naming the problem, exit 2, no
    traceback, no gait file."""
    out = tmp_path / "g.gait.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.run([sys.executable, "-m", "gaitopt", "solve", "--model",
                           str(DATA / file), "-o", str(out)], capture_output=True, text=True,
                          env=env, timeout=120, check=False)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), proc.stderr
    assert UNWALKABLE[file][0] in lines[0]
    assert "stage" not in proc.stdout and not out.exists()


def test_solve_with_a_gait_the_model_cannot_do_names_the_one_it_can(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["solve", "--model", "seven-link", "--gait", "walk",
                                      "-o", str(tmp_path / "g.gait.json")])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "heel and a toe on each foot" in lines[0]
    assert "(--gait heel-toe, the default)" in lines[0]
    assert not (tmp_path / "g.gait.json").exists()


@pytest.mark.slow
def test_the_seven_link_default_command_converges_and_verifies(tmp_path: Path) -> None:
    """``gaitopt solve --model seven-link`` with no other option: the heel-toe walk at
    72.2 m/min on 24 + 16 knots, its error estimate within 1 %, and ``verify`` passes
    (about 40-70 s)."""
    from gaitopt.gait.record.file import Gait

    out = tmp_path / "g.gait.json"
    result = CliRunner().invoke(cli, ["solve", "--model", "seven-link", "-o", str(out)])
    assert result.exit_code == 0, result.output
    gait = Gait.load(out)
    assert gait.options["gait"] == "heel-toe" and gait.speed * 60.0 == pytest.approx(
        72.23, abs=0.01)
    estimate = gait.solver["accuracy"]["cost_error"]
    assert abs(estimate) <= 0.01 * gait.cost_value
    verified = CliRunner().invoke(cli, ["verify", str(out)])
    assert verified.exit_code == 0, verified.output


@pytest.mark.parametrize(("model", "gait", "formulation"), [
    ("five-link", "walk", "reduced"), ("seven-link", "heel-toe", "full")])
def test_sweep_defaults_to_the_gait_the_model_allows(monkeypatch: pytest.MonkeyPatch,
                                                     tmp_path: Path, model: str, gait: str,
                                                     formulation: str) -> None:
    """``gaitopt sweep --model M`` without ``--gait``: the same gait as ``gaitopt solve``."""
    seen: dict[str, object] = {}

    def capture(**kwargs: object) -> object:
        seen.update(kwargs)
        raise SystemExit(0)

    monkeypatch.setattr("gaitopt.cli.study.make_spec", capture)
    result = CliRunner().invoke(cli, ["sweep", "-o", str(tmp_path / "s"), "--model", model,
                                      "--speeds", "30"])
    assert result.exit_code == 0, result.output
    problem = seen["problem"]
    assert isinstance(problem, dict)
    assert (problem["gait"], problem["formulation"]) == (gait, formulation)
