"""``gaitopt solve``: writes a verified gait file; refuses bad requests with one line (exit 2)
before solving; reports a failed solve (exit 1, no file, the failed stage named)."""

from __future__ import annotations

import functools
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner, Result

from gaitopt.analysis.verify import Check, VerifyReport, verify_gait
from gaitopt.cli import cli
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.record import MotionOutOfReachError
from tests.gait.conftest import SolveFn
from tests.gait.test_walking_errors import one_legged_model_file

ROOT = Path(__file__).resolve().parents[2]


def solve(*args: str) -> Result:
    return CliRunner().invoke(cli, ["solve", *args])


def test_solve_prints_a_summary_and_writes_a_gait_that_verifies(
        tmp_path: Path, solved: SolveFn) -> None:
    default_gait = solved(GaitOptions()).gait  # the API's default problem
    out = tmp_path / "walk.gait.json"
    result = solve("-o", str(out))
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    for stage in ("relaxed contact", "enforced contact", "ankle torques free"):
        assert f"stage {stage}" in text
    for item in ("0.2000 m/s (12.00 m/min)", "step length", "step time", "cost (energy per "
                 "metre)", "peak torque hip_1", "smallest normal force", "swing clearance",
                 "NLP size", "iterations", "wall time"):
        assert item in text, item
    assert f"wrote{out}" in "".join(result.output.split())  # rich may wrap a long path
    gait = Gait.load(out)
    assert gait.success and gait.options == default_gait.options
    # The same problem as the API's default solve, with the same optimum.
    assert gait.cost_value == pytest.approx(default_gait.cost_value, rel=1e-5)
    assert gait.step_length == pytest.approx(default_gait.step_length, rel=1e-5)
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # atomic: no temporary left
    verified = CliRunner().invoke(cli, ["verify", str(out)])
    assert verified.exit_code == 0, verified.output


def test_solve_keeps_verify_in_the_file(tmp_path: Path) -> None:
    """The solve runs verify's checks on its gait and keeps the outcome (``solver.verify``);
    ``--no-verify`` leaves it out."""
    out = tmp_path / "coarse.gait.json"
    result = solve("--knots", "4,3", "-o", str(out))
    assert result.exit_code == 0, result.output
    record = Gait.load(out).solver["verify"]
    independent = verify_gait(Gait.load(out))
    assert record["passed"] is True and independent.passed
    assert record["checks"] == len(independent.checks) and record["failed"] == []
    assert "verify: all" in result.output
    unchecked = tmp_path / "unchecked.gait.json"
    result = solve("--knots", "4,3", "--no-verify", "-o", str(unchecked))
    assert result.exit_code == 0, result.output
    assert "verify" not in Gait.load(unchecked).solver


def test_a_gait_verify_rejects_is_written_with_exit_status_4(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Never exit 0 with a gait that verify rejects: the file says which checks failed (the
    rejection stands in for a solve whose re-integration fails, e.g. a run under-resolved)."""
    def rejects(gait: Gait, **_: Any) -> VerifyReport:
        checks = verify_gait(gait).checks
        return VerifyReport(tuple(Check(c.id, 2 * c.limit + 1.0, c.limit, "made to fail")
                                  if c.id == "swing.reversals" else c for c in checks))

    # The solve verifies through gaitopt.analysis.plausible.Verifier (once per gait).
    monkeypatch.setattr("gaitopt.analysis.plausible.verify_gait", rejects)
    out = tmp_path / "rejected.gait.json"
    result = solve("--knots", "4,3", "-o", str(out))
    assert result.exit_code == 4, result.output
    text = " ".join(result.output.split())
    assert "VERIFY FAILS 1 of" in text and "swing.reversals (7 > 3 turns)" in text
    record = Gait.load(out).solver["verify"]
    assert record["passed"] is False
    assert [c["id"] for c in record["failed"]] == ["swing.reversals"]


@pytest.fixture
def no_solve(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("a solve was started for a request that should be refused")

    monkeypatch.setattr("gaitopt.gait.solve.staged.transcription_for", refuse)


BAD_REQUESTS: dict[str, tuple[list[str], tuple[str, ...]]] = {
    "negative speed": (["--speed", "-3m/min"], ("speed", "> 0")),
    "zero speed": (["--speed", "0m/min"], ("speed", "> 0")),
    "speed without a number": (["--speed", "fast"], ("--speed",)),
    "speed with an unknown unit": (["--speed", "3mph"], ("--speed", "unit")),
    "three knot counts": (["--knots", "8,5,3"], ("--knots",)),
    "knots not numbers": (["--knots", "a,b"], ("--knots",)),
    "too few knots": (["--knots", "2,5"], ("knots",)),
    "too many knots": (["--knots", "8,999"], ("knots",)),
    "step longer than the legs reach": (["--step-length", "2.5"], ("step_length", "reach")),
    "step length not a number": (["--step-length", "long"], ("--step-length",)),
    "single support fraction zero": (["--single-support", "0"], ("single_support_fraction",)),
    "negative friction": (["--friction", "-0.5"], ("friction",)),
    "unknown model": (["--model", "no-such-model"], ("no-such-model",)),
    "heel-toe without feet": (["--gait", "heel-toe"], ("heel-toe", "one contact point on each "
                                                                  "leg", "--gait walk")),
    "missing sequence file": (["--contact-sequence", "/no/such.yaml"], ("--contact-sequence",
                                                                        "No such file")),
}


@pytest.mark.parametrize(("text", "words"), [
    ("phases: [{name: a, held: [tip_1], fraction: 1.0}]\nevents: []\nanchors: {tip_1: 0}\n",
     ("contact sequence", "one event per phase")),
    ("phases: [{name: a, held: [foot_9], fraction: 1.0}]\n"
     "events: [{name: e, touchdown: [tip_2], release: [tip_1]}]\nanchors: {tip_1: 0}\n",
     ("'foot_9', not a contact",)),
    ("phases: oops\nevents: []\nanchors: {}\n", ("--contact-sequence", "phases = 'oops'")),
    ("phases: [\n", ("--contact-sequence", "not valid YAML")),
])
def test_bad_contact_sequence_file_exits_2_naming_it(no_solve: None, tmp_path: Path,
                                                     text: str, words: tuple[str, ...]) -> None:
    file = tmp_path / "seq.yaml"
    file.write_text(text)
    result = solve("--contact-sequence", str(file), "-o", str(tmp_path / "g.gait.json"))
    assert result.exit_code == 2, (result.output, result.exception)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    for word in words:
        assert word in lines[0], lines[0]


@pytest.mark.parametrize("case", list(BAD_REQUESTS))
def test_bad_request_exits_2_with_one_line_before_solving(no_solve: None, tmp_path: Path,
                                                          case: str) -> None:
    args, words = BAD_REQUESTS[case]
    out = tmp_path / "g.gait.json"
    result = solve(*args, "-o", str(out))
    assert result.exit_code == 2, (result.output, result.exception)
    assert isinstance(result.exception, SystemExit)  # a handled error, not a crash
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    for word in words:
        assert word in lines[0], lines[0]
    assert "stage" not in result.stdout and not out.exists()


def test_model_without_two_legs_exits_2(no_solve: None, tmp_path: Path) -> None:
    result = solve("--model", str(one_legged_model_file(tmp_path)), "-o",
                   str(tmp_path / "g.gait.json"))
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "two contact points" in lines[0]


def test_negative_speed_in_a_real_process_prints_no_traceback(tmp_path: Path) -> None:
    """The installed entry point (``python -m gaitopt``): one line on stderr, exit 2."""
    out = tmp_path / "g.gait.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.run([sys.executable, "-m", "gaitopt", "solve", "--speed", "-3m/min",
                           "-o", str(out)], capture_output=True, text=True, env=env,
                          timeout=120, check=False)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: ") and "speed" in lines[0]
    assert not out.exists()


def test_failed_solve_exits_1_names_the_stage_and_writes_nothing(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Forced failure: 3 IPOPT iterations per stage, no continuation (the CLI has no option
    for that, so the options it builds are patched)."""
    monkeypatch.setattr("gaitopt.cli.gait.GaitOptions",
                        functools.partial(GaitOptions, max_iter=3, continuation=False))
    out = tmp_path / "g.gait.json"
    result = solve("-o", str(out))
    assert result.exit_code == 1, result.output
    text = " ".join(result.output.split())
    assert "failed at stage 'relaxed contact' (Maximum_Iterations_Exceeded)" in text
    assert "What you can change" in text and "No gait file written" in text
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_motion_out_of_reach_exits_1_with_the_reason_and_writes_nothing(
        no_solve: None, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """A converged solution that cannot be recorded (its motion leaves a leg's reach between
    knots, see tests/gait/test_walking_errors.py) is a failed solve: the message says that it
    converged and why it is rejected, exit 1, no file."""
    class Converged:
        success = True

    def converged(*args: object, **kwargs: object) -> object:
        return Converged()

    def unrecordable(*args: object, **kwargs: object) -> Gait:
        raise MotionOutOfReachError("the solution's motion between knots leaves a leg's reach "
                                    "in phase double_support; solve on a finer grid")

    monkeypatch.setattr("gaitopt.gait.api.solve_staged_run", converged)
    monkeypatch.setattr("gaitopt.gait.solve.record.gait_from_run", unrecordable)
    out = tmp_path / "g.gait.json"
    result = solve("-o", str(out))
    assert result.exit_code == 1, result.output
    text = " ".join(result.output.split())
    assert "FAILED after the last stage, which converged" in text
    assert "leaves a leg's reach" in text and "finer grid" in text
    assert "No gait file written" in text and "Traceback" not in text
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_warm_start_from_a_gait_file_solves_a_nearby_speed_in_one_stage(
        tmp_path: Path, default_gait: Gait, default_gait_file: Path) -> None:
    out = tmp_path / "faster.gait.json"
    # default_gait_file holds the paper's problem: warm-start the same problem.
    result = solve("--paper-grid", "--speed", "12.6m/min", "--warm-start",
                   str(default_gait_file), "-o", str(out))
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "stage warm start" in text and "stage relaxed contact" not in text
    gait = Gait.load(out)
    assert gait.success and gait.speed == pytest.approx(0.21)
    # Energy per metre grows with speed near the optimum (paper Fig. 3).
    assert gait.cost_value > default_gait.cost_value
    # A gait of another variant is not used: the solve starts cold and says so.
    other = solve("--paper-grid", "--no-ankle", "--warm-start", str(default_gait_file), "-o",
                  str(tmp_path / "plain.gait.json"))
    assert other.exit_code == 0, other.output
    other_text = " ".join(other.output.split())  # rich wraps lines at the terminal width
    assert "starting cold" in other_text and "stage relaxed contact" in other_text
    # A missing or broken file is a one-line error before any solve.
    broken = tmp_path / "broken.gait.json"
    broken.write_text("{")
    bad = solve("--warm-start", str(broken), "-o", str(tmp_path / "x.gait.json"))
    assert bad.exit_code == 2 and "--warm-start" in " ".join(bad.output.split())
    assert "Traceback" not in bad.output


def test_a_coarse_grid_for_a_heel_toe_step_is_noted(no_solve: None, tmp_path: Path) -> None:
    """The seven-link heel-toe walk fails verify between knots on coarse grids
    (docs/feet.md): the solve says so before it starts (its default grid is 24 + 16)."""
    result = solve("--model", "seven-link", "--gait", "heel-toe", "--speed", "30m/min",
                   "--knots", "16,6", "-o", str(tmp_path / "g.gait.json"))
    text = " ".join(result.output.split())
    assert "full coordinates" in text
    assert "4-phase step on 16+6 knots is coarse" in text and "24,16" in text
