"""``verify_gait`` / ``gaitopt verify``: passes on a solved gait, fails, naming the right
check, on deliberately corrupted copies."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.analysis.verify import verify_gait
from gaitopt.cli import cli
from gaitopt.gait.gait_file import Gait
from gaitopt.gait.options import GaitOptions
from gaitopt.gait.walking import DOUBLE, SINGLE
from tests.gait.conftest import Reference, SolveFn, contact_forces, lowest_sample_normal_force

RefFn = Callable[..., Reference]
Corruption = Callable[[dict[str, Any]], None]

INTERVAL = "re-integration per interval"
COST = "cost recomputed from the controls (relative)"
TIPS = "held tips on the ground"
PERIODIC = "periodicity of states (legs relabelled)"
EVENTS = "impact and liftoff maps"
FORCE = "normal contact force on dense samples (negative part)"


def _torque(d: dict[str, Any]) -> None:
    d["phases"][0]["u"][3][0] += 5.0  # hip_1 at the 4th single-support knot, N m


def _step_length(d: dict[str, Any]) -> None:
    d["parameters"]["step_length"] *= 1.05


def _event_velocity(d: dict[str, Any]) -> None:
    d["events"][0]["qd_after"][2] += 0.05  # torso rate just after the heel strike, rad/s


def _knot_velocity(d: dict[str, Any]) -> None:
    d["phases"][1]["qd"][0][2] += 0.05  # the same at the first double-support knot


CORRUPTIONS: dict[str, tuple[Corruption, set[str]]] = {
    "knot torque": (_torque, {INTERVAL, COST}),
    "step length parameter": (_step_length, {TIPS, PERIODIC, COST}),
    "velocity after heel strike (event)": (_event_velocity, {EVENTS}),
    "velocity after heel strike (knot)": (_knot_velocity, {EVENTS}),
}


def _corrupted(gait: Gait, name: str) -> Gait:
    data = copy.deepcopy(gait.to_dict())
    CORRUPTIONS[name][0](data)
    return Gait.from_dict(data)


def test_verify_passes_on_the_default_gait(default_gait: Gait) -> None:
    report = verify_gait(default_gait)
    failed = [(c.name, c.value) for c in report.checks if not c.passed]
    assert report.passed, failed
    names = {c.name for c in report.checks}
    assert {INTERVAL, COST, TIPS, PERIODIC, EVENTS, FORCE} <= names
    assert report.check(COST).value < 1e-9
    assert report.check(PERIODIC).value < 1e-7


@pytest.mark.parametrize("name", list(CORRUPTIONS))
def test_verify_names_the_failing_check_of_a_corrupted_copy(default_gait: Gait,
                                                             name: str) -> None:
    report = verify_gait(_corrupted(default_gait, name))
    failed = {c.name for c in report.checks if not c.passed}
    assert not report.passed
    assert failed == CORRUPTIONS[name][1]


def test_cli_verify_passes_on_the_saved_default_gait(default_gait_file: Path) -> None:
    result = CliRunner().invoke(cli, ["verify", str(default_gait_file)])
    assert result.exit_code == 0, result.output
    assert "checks passed" in result.output and "FAIL" not in result.output


@pytest.mark.parametrize("name", list(CORRUPTIONS))
def test_cli_verify_exits_nonzero_on_a_corrupted_file(default_gait_file: Path, tmp_path: Path,
                                                      name: str) -> None:
    data = json.loads(default_gait_file.read_text())
    CORRUPTIONS[name][0](data)
    bad = tmp_path / "corrupted.gait.json"
    bad.write_text(json.dumps(data))
    result = CliRunner().invoke(cli, ["verify", str(bad)])
    assert result.exit_code == 1, result.output
    expected = CORRUPTIONS[name][1]
    summary = " ".join(result.output.split()).split(" check(s) FAILED: ")  # lines may wrap
    assert len(summary) == 2 and summary[0].endswith(str(len(expected)))
    for check in expected:
        assert check in summary[1]


def test_cli_verify_rejects_a_file_that_is_not_a_gait(tmp_path: Path) -> None:
    bad = tmp_path / "x.gait.json"
    bad.write_text('{"format": "something else", "version": 1}')
    result = CliRunner().invoke(cli, ["verify", str(bad)])
    assert result.exit_code == 2
    assert "format" in result.stderr and "Traceback" not in result.output


# -- a gait whose dense samples include the heel-strike instant ---------------------------------

FAST = GaitOptions(speed=0.5)  # 30 m/min: step time < 0.5 s, 101 samples, one at 0.85 T


def test_fast_gait_forces_between_knots_are_non_negative(solved: SolveFn,
                                                         reference: RefFn) -> None:
    """The 30 m/min gait's normal forces, recomputed with Pinocchio on the dense samples of
    each phase (single support: t <= heel strike; double support: t > heel strike), are
    non-negative. Its samples include one at the heel-strike instant, holding the
    pre-impact velocity (it belongs to single support)."""
    gait = solved(FAST).gait
    assert gait.success
    ref = reference(gait.model)
    s = gait.samples
    strike = next(e for e in gait.events if e.name == "heel_strike")
    at_strike = np.flatnonzero(np.abs(s.t - strike.t) < 1e-12)
    assert at_strike.size == 1
    np.testing.assert_allclose(s.qd[at_strike[0]], strike.qd_before, atol=1e-9)
    lowest = lowest_sample_normal_force(ref, gait)
    assert lowest >= -1e-3
    # Double-support forces at the pre-impact sample are what a check must not use.
    wrong = contact_forces(ref, s.q[at_strike[0]], s.qd[at_strike[0]], s.u[at_strike[0]],
                           ("tip_1", "tip_2"))
    assert np.min(wrong[:, 1]) < -100.0
    assert {ph.name for ph in gait.phases} == {SINGLE, DOUBLE}


def test_verify_force_check_passes_on_the_fast_gait(solved: SolveFn) -> None:
    report = verify_gait(solved(FAST).gait)
    assert report.check(FORCE).passed, report.check(FORCE)
