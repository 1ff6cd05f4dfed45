"""Running at people's speeds (docs/running.md): a given speed is not checked against the
bounds of a free speed, ``gaitopt solve --speed-bounds``, a run's defaults (no liftoff
impulse, the stance share free, longer steps), the seven-link run on its toes, and real runs
that converge and pass verify."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from gaitopt.analysis.verify import verify_gait
from gaitopt.cli import cli
from gaitopt.cli.base import UserError
from gaitopt.cli.gait import speed_bounds
from gaitopt.gait.api import solve_gait
from gaitopt.gait.formulations.full.constraints import CLEARANCE_PROFILE
from gaitopt.gait.formulations.select import biped_for, problem_for
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.options.model_defaults import (
    RUN_STANCE_BOUNDS,
    RUN_STEP_LENGTH_BOUNDS,
    RUN_SWING_CLEARANCE,
    gait_problem,
    options_for_model,
    run_stance_guess,
)
from gaitopt.gait.sequence.builtin import running_sequence
from gaitopt.robot import load_model


def _resolved(model: str, options: GaitOptions) -> GaitOptions:
    robot = load_model(model)
    resolved = options_for_model(robot, options)
    validate_options(resolved, biped_for(robot, resolved))
    return resolved


def test_a_given_speed_is_not_checked_against_the_bounds_of_a_free_speed() -> None:
    """240 m/min is far above the five-link biped's speed_bounds (90 m/min): asked for, it is
    the speed; only a speed <= 0 is refused."""
    run = GaitOptions(gait="run", impulse=False, speed=4.0)
    assert _resolved("five-link", run).speed == 4.0
    assert _resolved("five-link", GaitOptions(speed=4.0, speed_bounds=(0.1, 0.2))).speed == 4.0
    with pytest.raises(GaitOptionsError, match="speed = .*must be > 0"):
        _resolved("five-link", run.replace(speed=-1.0))


def test_speed_bounds_given_are_kept_and_checked() -> None:
    free = _resolved("seven-link", GaitOptions(speed=None, speed_bounds=(1.0, 6.0)))
    assert free.speed_bounds == (1.0, 6.0)  # not scaled with the model
    with pytest.raises(GaitOptionsError, match="speed_bounds .*lower bound must be <= upper"):
        _resolved("five-link", GaitOptions(speed=None, speed_bounds=(6.0, 1.0)))


@pytest.mark.parametrize(("text", "expected"), [
    ("60m/min,400m/min", (1.0, 400.0 / 60.0)),
    ("1m/s, 4 m/s", (1.0, 4.0)),
    ("0.5,2", (0.5, 2.0)),
    ("3.6km/h,3.6km/h", (1.0, 1.0)),
])
def test_speed_bounds_parse_with_units(text: str, expected: tuple[float, float]) -> None:
    assert speed_bounds(text) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(("text", "message"), [
    ("60m/min", "two speeds LO,HI"),
    ("1,2,3", "two speeds LO,HI"),
    ("60m/min,fast", "--speed-bounds: speed 'fast'"),
    ("60m/min,4furlong/s", "unknown unit"),
    ("400m/min,60m/min", "0 < LO <= HI"),
    ("0,60m/min", "0 < LO <= HI"),
])
def test_speed_bounds_errors_name_the_option(text: str, message: str) -> None:
    with pytest.raises(UserError, match=message) as info:
        speed_bounds(text)
    assert "--speed-bounds" in str(info.value)


def test_the_cli_refuses_bad_speed_bounds_and_an_impulse_in_a_run() -> None:
    runner = CliRunner()
    result = runner.invoke(cli, ["solve", "--speed", "free", "--speed-bounds", "2,1"])
    assert result.exit_code != 0 and "--speed-bounds" in result.output, result.output
    result = runner.invoke(cli, ["solve", "--gait", "run", "--impulse"])
    assert result.exit_code != 0, result.output
    assert "--impulse with --gait run" in result.output, result.output


def test_a_run_frees_its_stance_share_and_lengthens_its_steps() -> None:
    run = _resolved("five-link", GaitOptions(gait="run", impulse=False, speed=2.5))
    assert run.single_support_fraction == run_stance_guess(load_model("five-link"), 2.5)
    assert run.single_support_fraction_bounds == RUN_STANCE_BOUNDS
    assert run.step_length_bounds == pytest.approx(RUN_STEP_LENGTH_BOUNDS, rel=1e-12)
    assert run.formulation == "full"
    # a given share stays fixed; given bounds keep the guess within them
    fixed = _resolved("five-link", GaitOptions(gait="run", impulse=False,
                                               single_support_fraction=0.5))
    assert fixed.single_support_fraction == 0.5
    assert fixed.single_support_fraction_bounds is None
    bounded = _resolved("five-link", GaitOptions(gait="run", impulse=False,
                                                 single_support_fraction_bounds=(0.3, 0.6)))
    assert bounded.single_support_fraction == 0.6
    # the walk keeps 0.85, fixed, and its own step bounds
    walk = _resolved("five-link", GaitOptions())
    assert walk.single_support_fraction == 0.85
    assert walk.single_support_fraction_bounds is None
    assert walk.step_length_bounds == pytest.approx((0.02, 0.8), rel=1e-12)


def test_a_run_clears_its_swing_foot_over_the_stance() -> None:
    """A run on point feet has the default swing clearance :data:`RUN_SWING_CLEARANCE` times
    the leg length (the seven-link run on its toes none), held by the profile rows of the
    stance phase on the foot that lands after the flight (a given ``swing_clearance`` was
    ignored by a run before: its stance ends in no landing); a given clearance stays, and the
    walk keeps the paper's ``y >= 0``."""
    for name, leg in (("five-link", 1.0), ("adult-point-feet", 0.9275)):
        run = _resolved(name, GaitOptions(gait="run", impulse=False, speed=2.0))
        assert run.swing_clearance == pytest.approx(RUN_SWING_CLEARANCE * leg, rel=1e-3)
    given = _resolved("five-link", GaitOptions(gait="run", impulse=False, speed=2.0,
                                               swing_clearance=0.03))
    assert given.swing_clearance == 0.03
    none = _resolved("five-link", GaitOptions(gait="run", impulse=False, speed=2.0,
                                              swing_clearance=0.0))
    assert none.swing_clearance == 0.0  # the paper's y >= 0: no profile rows
    stance = problem_for(load_model("five-link"), none).phases[0]
    assert CLEARANCE_PROFILE not in [c.name for c in stance.path_constraints]
    assert _resolved("five-link", GaitOptions()).swing_clearance is None
    assert _resolved("seven-link", GaitOptions(gait="run", impulse=False,
                                               speed=2.0)).swing_clearance is None
    for name in ("five-link", "seven-link"):
        model = load_model(name)
        stance, flight = problem_for(model, _resolved(name, GaitOptions(
            gait="run", impulse=False, speed=2.0, swing_clearance=0.05))).phases
        assert CLEARANCE_PROFILE in [c.name for c in stance.path_constraints]
        assert CLEARANCE_PROFILE not in [c.name for c in flight.path_constraints]


def test_the_stance_share_guess_falls_with_the_froude_number() -> None:
    five, adult = load_model("five-link"), load_model("adult-point-feet")
    assert run_stance_guess(five, 1.0) == 0.9  # a walk's Froude number: the upper clip
    assert run_stance_guess(five, 2.0) == pytest.approx(0.95 - 0.3 * 4.0 / 9.81, rel=1e-12)
    assert run_stance_guess(five, 20.0) == 0.4
    assert run_stance_guess(adult, 2.5) > run_stance_guess(adult, 4.0)
    speed_free = _resolved("five-link", GaitOptions(gait="run", impulse=False, speed=None))
    assert speed_free.single_support_fraction == run_stance_guess(five, 0.2)
    fast = _resolved("five-link", GaitOptions(gait="run", impulse=False, speed=None,
                                              speed_bounds=(2.5, 6.0)))
    assert fast.single_support_fraction == run_stance_guess(five, 2.5)


def test_a_run_with_the_impulse_on_is_refused_by_name() -> None:
    with pytest.raises(GaitOptionsError, match="gait = 'run' with impulse on.*impulse=False"):
        _resolved("five-link", GaitOptions(gait="run", speed=2.5))


def test_the_seven_link_biped_runs_on_its_toes() -> None:
    model = load_model("seven-link")
    assert gait_problem(model, "run") is None
    sequence = running_sequence(model, 0.7)
    assert [p.held for p in sequence.phases] == [("toe_1",), ()]
    assert dict(sequence.anchors) == {"toe_1": 0.0, "toe_2": 1.0}
    run = _resolved("seven-link", GaitOptions(gait="run", impulse=False, speed=4.0))
    assert run.knots == (16, 6)


@pytest.mark.parametrize("speed", [1.0, 1.5, 2.0])
def test_a_five_link_run_converges_and_verifies(speed: float) -> None:
    """The default run of the five-link biped (stance share free, no impulse, the swing
    clearance) at 60, 90 and 120 m/min converges and passes verify (the model's 50 N m hips
    and knees cannot run at 150 m/min). Without the clearance the swing foot grazed the
    ground at the other leg's mid-stance and the knee turned 4 and 6 times at 90 and 120
    m/min, failing ``swing.reversals`` (docs/running.md, "The swing of a run")."""
    gait = solve_gait("five-link", GaitOptions(gait="run", impulse=False, speed=speed))
    assert gait.success
    assert gait.speed == pytest.approx(speed, rel=1e-9)
    assert gait.solver["accuracy"]["within_target"]
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


def test_a_run_at_150_m_per_min_converges_and_verifies() -> None:
    """The adult with point feet (the seven-link body) runs at 150 m/min from the defaults:
    converged to the default accuracy, verify passes, a step of about a metre with a flight."""
    gait = solve_gait("adult-point-feet", GaitOptions(gait="run", impulse=False, speed=2.5))
    assert gait.success
    assert gait.speed == pytest.approx(2.5, rel=1e-9)
    assert gait.solver["accuracy"]["within_target"]
    assert 0.6 < gait.step_length < 1.4  # measured 0.99 m
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


def test_a_free_speed_run_starts_within_its_speed_bounds() -> None:
    """Speed free within 150-400 m/min (``--speed-bounds 150m/min,400m/min``): the solve
    starts at the bound nearest the reference speed (12 m/min), not outside the bounds, and
    the run's cost per metre grows with the speed, so the optimum is the lower bound."""
    gait = solve_gait("adult-point-feet", GaitOptions(gait="run", impulse=False, speed=None,
                                                      speed_bounds=(2.5, 6.0)))
    assert gait.success
    assert gait.speed == pytest.approx(2.5, rel=1e-5)  # measured: the bound
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


@pytest.mark.slow
@pytest.mark.parametrize("speed_m_min", [150.0, 240.0])
def test_a_seven_link_run_converges_and_verifies(speed_m_min: float) -> None:
    """The seven-link run on its toes at 150 and 240 m/min from the defaults converges and
    passes verify (measured 3-30 s a solve with a warm compile cache, docs/running.md)."""
    gait = solve_gait("seven-link", GaitOptions(gait="run", impulse=False,
                                                speed=speed_m_min / 60.0))
    assert gait.success
    assert gait.solver["accuracy"]["within_target"]
    report = verify_gait(gait)
    assert report.passed, report.failed_ids


@pytest.mark.slow
def test_a_seven_link_run_at_400_m_per_min_resolves_its_flight() -> None:
    """At 400 m/min the seven-link run's flight takes about 65 % of the step: its knots follow
    the stance's density, and the re-integration of every interval passes
    (``integration.interval``, which failed on main's 6 flight knots). Without a plausibility
    check this optimum fails ``swing.reversals``, its ankle on its joint limit, which
    ``gaitopt solve`` mends with its torque-rate fallback
    (tests/gait/test_torque_rate_fallback.py, docs/running.md)."""
    gait = solve_gait("seven-link", GaitOptions(gait="run", impulse=False, speed=400.0 / 60.0))
    assert gait.success
    assert gait.solver["accuracy"]["within_target"]
    stance, flight = gait.phases
    share = (stance.t[-1] - stance.t[0]) / gait.step_time
    assert share < 0.5  # measured 0.355: the flight is the long phase
    stance_density = (stance.t.size - 1) / share
    flight_density = (flight.t.size - 1) / (1.0 - share)
    # The knots follow the share's first guess (0.4: 16 + 24); the optimum's 0.355 leaves
    # the flight at 0.84 of the stance's density (measured). 16 + 6 had 0.18 of it.
    assert flight_density >= 0.6 * stance_density
    assert verify_gait(gait).check("integration.interval").passed
