"""``gaitopt study --walk-run`` through click's CliRunner: its errors, and one small real
study of the five-link biped (two speeds, coarse knots) that resumes."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.study.summary import SUMMARY_FILE, read_summary
from gaitopt.study.walk_run import TABLE_FILE, TRANSITIONS_FILE, WALK_RUN_FILE, read_table


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner(env={"COLUMNS": None})


@pytest.mark.parametrize(("args", "words"), [
    (["--costs"], "--walk-run and --costs are two studies"),
    (["--cost", "work"], "--cost work: not with --walk-run"),
    (["--paper-grid"], "--paper-grid: not with --walk-run"),
    (["--speeds", "60"], "speeds: at least two speeds"),
    (["--speeds", "fast"], "--speeds: 'fast' is not a speed"),
    (["--knots", "8"], "--knots: '8' must be two integers"),
    (["--knots", "1,5"], "knots: \\(1, 5\\); allowed: two counts >= 2"),
    (["--model", "no-such-model"], "no-such-model"),
    (["--model", "five-link", "--model", "five-link"], "two models share a name"),
])
def test_bad_input_is_a_usage_error(runner: CliRunner, tmp_path: Path, args: list[str],
                                    words: str) -> None:
    result = runner.invoke(cli, ["study", "--walk-run", "-o", str(tmp_path / "s"),
                                 "--workers", "0", *args])
    assert result.exit_code == 2, result.output
    assert re.search(words, result.output), result.output
    assert not (tmp_path / "s" / "five-link").exists()  # nothing solved


@pytest.mark.slow
def test_small_study_runs_and_resumes(runner: CliRunner, tmp_path: Path) -> None:
    """Five-link, paper cost, 30 and 60 m/min on 8 + 5 knots: every branch converges at
    both speeds (measured: about 40 s in this process on a loaded 2-core machine)."""
    out = tmp_path / "wr"
    args = ["study", "--walk-run", "--model", "five-link", "--cost", "paper", "--speeds",
            "30,60", "--knots", "8,5", "--workers", "0", "-o", str(out)]
    result = runner.invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert (out / WALK_RUN_FILE).exists() and (out / TRANSITIONS_FILE).exists()
    assert (out / "report" / "report.html").exists()
    rows = read_table(out / TABLE_FILE)
    assert {(r.branch, r.speed_m_min) for r in rows} == {
        (b, v) for b in ("walk", "walk-single-support", "run") for v in (30.0, 60.0)}
    for r in rows:
        assert r.success, r
        assert math.isfinite(r.cost_value) and r.cost_value > 0
        # every point solved its check grid: the estimate is there, and below the cost
        assert math.isfinite(r.cost_error) and abs(r.cost_error) < r.cost_value
    for v in (30.0, 60.0):
        at = [r for r in rows if r.speed_m_min == v]
        assert sum(r.cheapest for r in at) == 1
        assert next(r for r in at if r.cheapest).cost_value == min(r.cost_value for r in at)
    assert "walk.low_speed" in result.output and "Froude" in (out / "report" /
                                                               "report.html").read_text()
    again = runner.invoke(cli, args)
    assert again.exit_code == 0, again.output
    assert "0 to solve" in again.output
    assert not re.search(r"^(ok  |FAIL) ", again.output, re.M)  # no point solved again
    summary = read_summary(out / "five-link" / "paper" / "run" / SUMMARY_FILE)
    assert all(r.success for r in summary) and len(summary) == 2
