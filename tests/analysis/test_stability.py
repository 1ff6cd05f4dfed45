"""Orbital stability (``gaitopt.analysis.stability``, ``gaitopt.analysis.return_map``).

Independent references: central finite differences of the simulated return map (against the
variational equations and saltation matrices), finite differences of the guard-crossing map on
its own (against the saltation matrix), and the passive compass-gait walker of Goswami,
Thuilot and Espiau (1998), whose stable period-one gait on a 3 degree slope is known.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.analysis.return_map import (
    PhaseProfile,
    StepEvent,
    StepSpec,
    event_jump,
    impact_jump,
    integrate_phase,
    phase_field,
    reference_step,
    saltation_matrix,
    simulate_step,
)
from gaitopt.analysis.stability import (
    StabilityError,
    analyse_step,
    gait_stability,
    gait_start,
    newton_fixed_point,
    step_from_gait,
)
from gaitopt.cli import cli
from gaitopt.gait.api import solve_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.robot import RobotModel, load_model

DATA = Path(__file__).parent / "data"
SLOPE = np.radians(3.0)
#: PD gains used on the five-link gait (N m/rad, N m s/rad).
GAINS = (300.0, 30.0)


# -- fixtures ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def gait() -> Gait:
    """The paper's problem at 12 m/min on the coarse grid (8 + 5 knots), a few seconds."""
    return solve_gait("five-link", GaitOptions.paper(speed=0.2))


@pytest.fixture(scope="module")
def compass() -> StepSpec:
    """The passive compass gait: single support until the swing tip strikes ahead of the
    stance tip (mid-stance scuffing ignored), then the impact of the swing tip alone."""
    model = load_model(DATA / "compass.yaml")
    free = PhaseProfile(contacts=("tip_1",), duration=None, t=np.array([0.0, 1.0]),
                        u=np.zeros((2, 0)), nominal_duration=1.0)
    strike = StepEvent("strike", "tip_2", ("tip_2",))
    return StepSpec(model=model, stance="tip_1", swing="tip_2", phases=(free,),
                    events=((strike,),), rtol=1e-10, atol=1e-10)


#: Indices in the compass walker's state [q; qd] (nq = 5: x, y, hip, hip_1, hip_2).
NQ = 5
STANCE, SWING = 3, 4                       # hip_1, hip_2: leg angles (the hip link level)
LEG_STATE = [STANCE, SWING, NQ + STANCE, NQ + SWING]


def compass_state(model: RobotModel, stance: float, swing: float, stance_rate: float,
                  swing_rate: float) -> np.ndarray:
    """``[q; qd]`` with the stance tip at the origin at rest and the hip link level: leg
    angles from the slope normal (rad, CCW), rates (rad/s)."""
    q = np.array([-np.sin(stance), np.cos(stance), 0.0, stance, swing])
    qd = np.array([-np.cos(stance) * stance_rate, -np.sin(stance) * stance_rate, 0.0,
                   stance_rate, swing_rate])
    assert model.coordinate_names == ("x", "y", "hip", "hip_1", "hip_2") and model.nq == NQ
    return np.concatenate([q, qd])


# -- the compass gait ---------------------------------------------------------------------------

def test_compass_two_period_one_gaits_longer_step_stable(compass: StepSpec) -> None:
    """Newton on the simulated return map from two starts finds two period-one gaits; the
    longer-step one is stable, the shorter-step one unstable; both monodromies agree with
    finite differences of the simulated map.

    Reference for the stable gait: Goswami, Thuilot and Espiau, "A study of the passive gait
    of a compass-like biped robot: symmetry and chaos", IJRR 17(12), 1998 (hip mass 10 kg,
    leg masses 5 kg, a = b = 0.5 m, slope 3 deg). Its fixed point just after the impact, as
    quoted by Spong and Bhatia, "Further results on control of the compass gait biped"
    (IROS 2003), in angles from the vertical: stance 0.2187 rad, swing -0.3234 rad, rates
    -1.0918 and -0.3772 rad/s (clockwise positive). From the slope normal that is a half
    inter-leg angle of (0.2187 + 0.3234) / 2 = 0.2711 rad (0.2187 + 3 deg = 0.2711), a step
    of 2 sin(0.2711) = 0.5355 m, and in our counter-clockwise convention rates -1.0918 (the
    stance leg) and -0.3772 (the swing leg).
    """
    model = compass.model
    long_gait = newton_fixed_point(compass, compass_state(model, 0.25, -0.25, -1.0, -0.3))[0]
    short_gait = newton_fixed_point(compass, compass_state(model, 0.1, -0.1, -0.3, 1.0))[0]
    # The literature's stable gait (4 digits quoted).
    np.testing.assert_allclose(long_gait[LEG_STATE], [0.2711, -0.2711, -1.0918, -0.3772],
                               atol=1.5e-3)
    steps = [2 * np.sin(y[STANCE]) for y in (long_gait, short_gait)]
    assert steps[0] == pytest.approx(0.5355, abs=2e-3)
    assert steps[1] < steps[0] - 0.01, steps
    # Symmetric gaits: legs at +-alpha at the start of the step (both tips on the slope).
    for y in (long_gait, short_gait):
        assert y[STANCE] == pytest.approx(-y[SWING], abs=1e-8)

    # The compass map is smooth: a larger difference step than the default suits it.
    stable = analyse_step(compass, long_gait, fd_step=1e-5)
    unstable = analyse_step(compass, short_gait, fd_step=1e-5)
    assert stable.verdict == "stable", stable.multipliers
    assert unstable.verdict == "unstable", unstable.multipliers
    assert stable.spectral_radius < 0.9
    assert unstable.spectral_radius > 1.1
    for rep in (stable, unstable):
        assert rep.residual < 1e-6
        assert rep.fd_agreement is not None and rep.fd_agreement < 1e-4, rep.fd_agreement
        # 2 nq = 10 minus 4 stance-tip constraints minus 2 for the free hip rotation.
        assert rep.multipliers.size == 4
        names = [r.name for r in rep.removed]
        assert any("free rotation of link hip" in n for n in names), names
        hip = next(r for r in rep.removed if "hip" in r.name)
        np.testing.assert_allclose(np.abs(hip.multipliers), 1.0, atol=1e-5)
        # Autonomous map: a shift along the orbit does not change the next start -> a zero
        # multiplier along the flow.
        f = phase_field(compass, compass.phases[0], 0.0, rep.state)
        ft = rep.basis.T @ f
        assert np.linalg.norm(rep.section_monodromy @ ft) < 1e-6 * np.linalg.norm(ft)
        assert np.min(np.abs(rep.multipliers)) < 1e-6


def test_compass_map_is_not_the_identity_off_the_fixed_point(compass: StepSpec) -> None:
    """The literature's state, 4 digits, is periodic to about 1e-3 (not exactly): the map is
    sensitive to the state, and its residual is reported."""
    y = compass_state(compass.model, 0.2711, -0.2711, -1.0918, -0.3772)
    step = simulate_step(compass, y)
    residual = np.max(np.abs(step.y_next - y))
    assert 1e-5 < residual < 5e-3
    assert step.step_time == pytest.approx(0.7343, abs=5e-3)


def test_linearizing_about_knots_reproduces_the_simulated_monodromy(compass: StepSpec) -> None:
    """``about="gait"`` (variational equations along interpolated knots) equals the
    simulated map's variational monodromy when the knots are the simulated orbit."""
    y = newton_fixed_point(compass, compass_state(compass.model, 0.25, -0.25, -1.0, -0.3))[0]
    step = simulate_step(compass, y, variational=True)
    t = np.linspace(0.0, step.strike_time, 121)
    states = [y]
    for a, b in zip(t[:-1], t[1:], strict=True):
        states.append(integrate_phase(compass, compass.phases[0], states[-1], until=b, tau0=a)[1])
    ys = np.array(states)
    acc = np.array([phase_field(compass, compass.phases[0], 0.0, s)[NQ:] for s in ys])
    knots = PhaseProfile(contacts=("tip_1",), duration=None, t=t,
                         u=np.zeros((t.size, 0)), q=ys[:, :NQ], qd=ys[:, NQ:], qdd=acc,
                         nominal_duration=step.strike_time)
    ref = reference_step(dataclasses.replace(compass, phases=(knots,), _functions={}))
    assert step.monodromy is not None and ref.monodromy is not None
    scale = np.max(np.abs(step.monodromy))
    assert np.max(np.abs(ref.monodromy - step.monodromy)) < 1e-4 * scale
    # Without the guard term the result is far off: the check can fail.
    d_delta = impact_jump(compass, ref.y_strike)[1]
    wrong = ref.factors["jump_swap"] @ d_delta @ ref.factors["phi_0"]
    assert np.max(np.abs(wrong - step.monodromy)) > 1e-2 * scale


# -- the five-link gait -------------------------------------------------------------------------

def test_saltation_matrix_matches_finite_differences_of_the_crossing(gait: Gait) -> None:
    """Across the heel strike, from ``tau_a`` (5 ms before the crossing) to ``t_b`` (5 ms
    after it) on one clock (double support's clock offset by ``t* - t*_0 + c``, so that it runs
    with absolute time whatever the crossing time ``t*``): Jacobian = Phi_double Xi
    Phi_single with the classical saltation matrix Xi; central differences of that map on its
    own agree; the plain composition of the flows and the impact Jacobian does not."""
    spec = step_from_gait(gait, pd=GAINS, rtol=1e-12)
    single, double = spec.phases
    y0 = gait_start(gait)
    strike = simulate_step(spec, y0).strike_time
    tau_a, t_b, c = strike - 5e-3, strike + 5e-3, 1e-3
    y_a = integrate_phase(spec, single, y0, until=tau_a)[1]

    def window(y: np.ndarray, variational: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
        t1, y_minus, phi1 = integrate_phase(spec, single, y, tau0=tau_a, guard=True,
                                            variational=variational)
        y_plus = impact_jump(spec, y_minus)[0]
        _, y_end, phi2 = integrate_phase(spec, double, y_plus, tau0=t1 - strike + c,
                                         until=t_b - strike + c, variational=variational)
        if not variational:
            return y_end, None
        assert phi1 is not None and phi2 is not None
        f_minus = phase_field(spec, single, t1, y_minus)
        f_plus = phase_field(spec, double, t1 - strike + c, y_plus)
        xi = saltation_matrix(spec, y_minus, f_minus, f_plus)
        return y_end, phi2 @ xi @ phi1

    _, jac = window(y_a, variational=True)
    assert jac is not None
    h, n = 1e-7, y_a.size
    fd = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fd[:, j] = (window(y_a + e)[0] - window(y_a - e)[0]) / (2 * h)
    scale = np.max(np.abs(jac))
    assert np.max(np.abs(fd - jac)) < 1e-5 * scale, np.max(np.abs(fd - jac)) / scale
    # The crossing matters: the plain composition of the flows and the impact Jacobian misses.
    t1, y_minus, phi1 = integrate_phase(spec, single, y_a, tau0=tau_a, guard=True,
                                        variational=True)
    y_plus, d_delta = impact_jump(spec, y_minus)
    assert phi1 is not None
    naive = integrate_phase(spec, double, y_plus, tau0=t1 - strike + c,
                            until=t_b - strike + c, variational=True)[2]
    assert naive is not None
    assert np.max(np.abs(naive @ d_delta @ phi1 - fd)) > 1e-2 * scale


@pytest.mark.slow
def test_five_link_monodromies_agree(gait: Gait) -> None:
    """Variational and finite-difference monodromies of the five-link gait's return map (PD
    tracking, so that the simulated step lands) agree to 1e-4 (about 30 s)."""
    rep = gait_stability(gait, pd=GAINS, check=True)
    assert rep.fd_agreement is not None and rep.fd_agreement < 1e-4, rep.fd_agreement
    assert rep.multipliers.size == 2 * gait.model.nq - 4


def test_open_loop_gait_is_violently_unstable(gait: Gait) -> None:
    """Linearized about the gait's own knots (the open-loop replay drifts off the orbit), the
    optimal gait has multipliers far outside the unit circle; its periodicity residual is the
    transcription's (the knots' own)."""
    rep = gait_stability(gait, about="gait")
    assert rep.verdict == "unstable"
    assert rep.spectral_radius > 1e3
    assert rep.start_residual < 1e-6
    assert rep.fd_agreement is None
    assert rep.multipliers.size == 2 * gait.model.nq - 4
    assert "linearized" in rep.fixed_point


# -- bad input ----------------------------------------------------------------------------------

def test_failed_gait_is_refused(gait: Gait, tmp_path: Path) -> None:
    failed = dataclasses.replace(gait, solver={**gait.solver, "success": False,
                                               "status": "Maximum_Iterations_Exceeded"})
    with pytest.raises(StabilityError, match="did not converge"):
        gait_stability(failed)
    with pytest.raises(StabilityError, match="pd: got"):
        step_from_gait(gait, pd=(-1.0, 2.0))
    path = failed.save(tmp_path / "failed.gait.json", allow_failed=True)
    out = tmp_path / "report.json"
    result = CliRunner().invoke(cli, ["stability", str(path), "--json", str(out)])
    assert result.exit_code == 2, result.output
    assert "did not converge" in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert "Traceback" not in result.output
    assert not out.exists()


def test_corrupted_file_and_bad_gains_are_refused(gait: Gait, tmp_path: Path) -> None:
    good = gait.save(tmp_path / "good.gait.json")
    bad = tmp_path / "bad.gait.json"
    bad.write_text(good.read_text()[:5000])
    out = tmp_path / "report.json"
    for args, text in (([str(bad)], "not valid JSON"),
                       ([str(tmp_path / "missing.gait.json")], "no such file"),
                       ([str(good), "--pd", "300"], "--pd"),
                       ([str(good), "--pd", "300,-1"], "--pd")):
        result = CliRunner().invoke(cli, ["stability", *args, "--json", str(out)])
        assert result.exit_code == 2, result.output
        assert text in result.output
        assert len(result.output.strip().splitlines()) == 1, result.output
        assert not out.exists()


def test_cli_prints_multipliers_and_writes_json(gait: Gait, tmp_path: Path) -> None:
    path = gait.save(tmp_path / "g.gait.json")
    out = tmp_path / "report.json"
    result = CliRunner().invoke(cli, ["stability", str(path), "--about", "gait", "--json",
                                      str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "spectral radius" in text and "UNSTABLE" in text
    data = json.loads(out.read_text())
    assert data["verdict"] == "unstable"
    assert len(data["multipliers"]) == 2 * gait.model.nq - 4
    assert data["removed"][0]["count"] == 4


def test_cli_reports_a_replay_that_never_lands(gait: Gait, tmp_path: Path) -> None:
    """The coarse gait's open-loop replay leaves the orbit before the heel strike: one line,
    exit status 1, nothing written."""
    path = gait.save(tmp_path / "g.gait.json")
    out = tmp_path / "report.json"
    result = CliRunner().invoke(cli, ["stability", str(path), "--json", str(out)])
    assert result.exit_code == 1, result.output
    text = " ".join(result.output.split())
    assert text.startswith("FAILED") and "did not strike" in text and "--pd" in text
    assert "Traceback" not in result.output
    assert not out.exists()


@pytest.fixture(scope="module")
def single_support_gait() -> Gait:
    """A walk without double support (``single_support_fraction = 1``), 8 knots."""
    return solve_gait("five-link", GaitOptions.paper(speed=0.2, single_support_fraction=1.0))


def test_single_support_walk_strikes_and_lifts_off_at_once(single_support_gait: Gait) -> None:
    """Without double support the heel strike (the striking tip alone) and the liftoff of the
    stance tip (no impulse) both end the one phase; linearized about its knots the gait is
    open-loop unstable and periodic to the transcription's accuracy."""
    spec = step_from_gait(single_support_gait, pd=GAINS)
    assert len(spec.phases) == 1 and spec.phases[0].duration is None
    (strike, liftoff), = spec.events
    assert (strike.kind, strike.contact, strike.contacts) == ("strike", "tip_2", ("tip_2",))
    assert (liftoff.kind, liftoff.contact, liftoff.contacts) == ("liftoff", "tip_1", ("tip_2",))
    assert liftoff.magnitude == 0.0
    rep = gait_stability(single_support_gait, about="gait")
    assert rep.verdict == "unstable" and rep.start_residual < 1e-6


@pytest.mark.slow
def test_single_support_walk_monodromies_agree(single_support_gait: Gait) -> None:
    """With PD the variational and finite-difference monodromies agree (about 8 s)."""
    rep = gait_stability(single_support_gait, pd=GAINS)
    assert rep.fd_agreement is not None and rep.fd_agreement < 1e-4, rep.fd_agreement
    assert rep.residual < 0.05
    assert rep.multipliers.size == 2 * single_support_gait.model.nq - 4


# -- a run: stance, toe-off, flight, touchdown ----------------------------------------------------

@pytest.fixture(scope="module")
def run_gait() -> Gait:
    """A run (stance on tip 1, then flight), full coordinates, 60 m/min, 8 + 5 knots: about
    2 s."""
    # the stance share fixed at 0.85, the walk's step bounds and y >= 0 (a run's defaults free
    # the share, allow longer steps and on point feet hold the swing foot above a clearance:
    # docs/running.md)
    return solve_gait("five-link", GaitOptions.paper(speed=1.0, formulation="full", gait="run",
                                                     impulse=False, single_support_fraction=0.85,
                                                     step_length_bounds=(0.02, 0.8),
                                                     swing_clearance=0.0))


def test_run_step_follows_its_contact_sequence(run_gait: Gait) -> None:
    """The run's return map: stance for its recorded duration, the toe-off (a liftoff without
    impulse, nothing held after it), flight until the swing tip strikes (the guard), the
    touchdown impact of the swing tip alone. With PD tracking the simulated step lands within
    a millisecond of the gait's own touchdown and comes back near its start."""
    assert [ph.contacts for ph in run_gait.phases] == [("tip_1",), ()]
    spec = step_from_gait(run_gait, pd=GAINS)
    stance, flight = spec.phases
    assert stance.duration == pytest.approx(run_gait.phases[0].duration)
    assert flight.duration is None and flight.contacts == ()
    (toe_off,), (touchdown,) = spec.events
    assert (toe_off.kind, toe_off.contact, toe_off.contacts, toe_off.magnitude) == (
        "liftoff", "tip_1", (), 0.0)
    assert (touchdown.kind, touchdown.contact, touchdown.contacts) == (
        "strike", "tip_2", ("tip_2",))
    y0 = gait_start(run_gait)
    step = simulate_step(spec, y0)
    assert step.strike_time == pytest.approx(run_gait.phases[1].duration, abs=1e-3)
    assert step.step_time == pytest.approx(run_gait.step_time, abs=1e-3)
    # In flight nothing is held: the toe-off without impulse leaves the velocities as they are.
    y_toe_off = integrate_phase(spec, stance, y0)[1]
    assert np.max(np.abs(event_jump(spec, toe_off, y_toe_off)[0] - y_toe_off)) < 1e-12
    assert np.max(np.abs(step.y_next - y0)) < 0.05


def test_run_linearized_about_its_knots_is_periodic_and_unstable(run_gait: Gait) -> None:
    """About its own knots the open-loop run is periodic to the transcription's accuracy and,
    like the walks, open-loop unstable."""
    rep = gait_stability(run_gait, about="gait")
    assert rep.start_residual < 1e-6
    assert rep.multipliers.size == 2 * run_gait.model.nq - 4
    assert rep.verdict == "unstable"


@pytest.mark.slow
def test_run_monodromies_agree(run_gait: Gait) -> None:
    """With PD (300, 30) the variational monodromy of the run (through the toe-off, the flight
    and the touchdown's saltation) agrees with central differences of the simulated map, at
    the gait's start and at the Newton fixed point (about 25 s)."""
    rep = gait_stability(run_gait, pd=GAINS)
    assert rep.fd_agreement is not None and rep.fd_agreement < 1e-4, rep.fd_agreement
    fixed = gait_stability(run_gait, pd=GAINS, fixed_point="newton")
    assert fixed.residual < 1e-8
    assert fixed.fd_agreement is not None and fixed.fd_agreement < 1e-4, fixed.fd_agreement


def test_cli_analyses_a_run(run_gait: Gait, tmp_path: Path) -> None:
    path = run_gait.save(tmp_path / "run.gait.json")
    out = tmp_path / "run.json"
    result = CliRunner().invoke(cli, ["stability", str(path), "--about", "gait", "--json",
                                      str(out)])
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    assert data["verdict"] == "unstable"
    assert len(data["multipliers"]) == 2 * run_gait.model.nq - 4


def test_report_analyses_in_worker_processes_equal_those_in_this_one(gait: Gait,
                                                                     tmp_path: Path) -> None:
    """The report's analyses of gait files in two local processes (started at once, collected
    later) give the rows the same analyses give in this process, in the files' order."""
    from gaitopt.viz.stability_table import stability_rows, start_stability_rows

    path = gait.save(tmp_path / "optimum.gait.json")
    failed = dataclasses.replace(gait, solver={**gait.solver, "success": False,
                                               "status": "Infeasible_Problem_Detected"})
    bad = failed.save(tmp_path / "failed.gait.json", allow_failed=True)
    rows = start_stability_rows([("optimum", gait, path), ("failed", failed, bad)],
                                workers=2)()
    (here,) = stability_rows([("optimum", Gait.load(path))])
    assert [r.label for r in rows] == ["optimum", "failed"]
    for cell, expected in ((rows[0].open_loop, here.open_loop),
                           (rows[0].tracked, here.tracked)):
        assert cell.report is not None and expected.report is not None
        assert cell.report.spectral_radius == pytest.approx(expected.report.spectral_radius,
                                                            rel=1e-9)
        assert cell.report.verdict == expected.report.verdict
    assert rows[1].open_loop.report is None and "did not converge" in rows[1].open_loop.text()
    assert rows[1].tracked.report is None


def test_report_table_shows_both_analyses_of_a_gait(gait: Gait) -> None:
    from gaitopt.viz.stability_table import REPORT_PD, stability_rows, stability_table_html

    (row,) = stability_rows([("optimum", gait)])
    about = gait_stability(gait, about="gait", check=False)
    tracked = gait_stability(gait, pd=REPORT_PD, check=False)
    assert row.open_loop.report is not None and row.tracked.report is not None
    assert row.open_loop.report.spectral_radius == pytest.approx(about.spectral_radius, rel=1e-9)
    assert row.tracked.report.spectral_radius == pytest.approx(tracked.spectral_radius, rel=1e-9)
    table = stability_table_html([row])
    assert f"{about.spectral_radius:.3g} (unstable" in table
    assert f"{tracked.spectral_radius:.3g} ({tracked.verdict}" in table
    # a gait the return map cannot replay shows why instead of a number
    failed = dataclasses.replace(gait, solver={**gait.solver, "success": False,
                                               "status": "Infeasible_Problem_Detected"})
    (bad,) = stability_rows([("failed", failed)])
    assert bad.open_loop.report is None and "did not converge" in bad.open_loop.text()
