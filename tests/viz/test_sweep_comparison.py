"""Sweeps side by side (``gaitopt report SWEEP --compare OTHER``): the figure draws every
solved point of both sweeps where it belongs, the table carries each sweep's optimum and
people's walk, and a folder without a sweep is refused by name."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.study.findings import HUMAN_OPTIMAL_SPEED_M_MIN, HUMAN_STEP_LENGTH
from gaitopt.study.summary import SummaryRow
from gaitopt.viz.sweep_comparison import (
    comparison_figure,
    comparison_table_html,
    load_compared_sweep,
)
from tests.viz.synthetic import synthetic_sweep


@pytest.fixture(scope="module")
def sweeps(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, list[SummaryRow]]:
    root = tmp_path_factory.mktemp("compare")
    synthetic_sweep(root / "a", speeds_m_min=(6, 12, 24), n_samples=21)
    other = synthetic_sweep(root / "b", speeds_m_min=(30, 45, 60), free=False, n_samples=21)
    return root / "a", root / "b", other


def line_data(fig: object, gid: str) -> tuple[np.ndarray, np.ndarray]:
    axes = fig.axes  # type: ignore[attr-defined]
    for line in axes[0].get_lines():
        if line.get_gid() == gid:
            return np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
    raise AssertionError(f"no line {gid}")


def test_figure_draws_each_sweeps_points(sweeps: tuple[Path, Path, list[SummaryRow]]) -> None:
    a, b, other_rows = sweeps
    compared = [load_compared_sweep(a), load_compared_sweep(b)]
    fig = comparison_figure(compared)
    x, y = line_data(fig, "sweep1:plain")
    plain = sorted((r.speed_m_min, r.cost) for r in other_rows
                   if r.variant == "plain" and r.speed_mode == "fixed")
    np.testing.assert_allclose(x, [p[0] for p in plain])
    np.testing.assert_allclose(y, [p[1] for p in plain])
    x, _ = line_data(fig, "sweep0:optimum:ankle")
    np.testing.assert_allclose(x, [np.sqrt(150.0)])  # the synthetic speed-free optimum
    # people's walk on the step-length axis
    marks = [ln for ln in fig.axes[1].get_lines() if ln.get_label() == "people's walk"]
    assert marks and marks[0].get_xdata()[0] == HUMAN_OPTIMAL_SPEED_M_MIN
    assert marks[0].get_ydata()[0] == HUMAN_STEP_LENGTH


def test_table_has_each_optimum_and_people(sweeps: tuple[Path, Path, list[SummaryRow]]) -> None:
    a, b, other_rows = sweeps
    table = comparison_table_html([load_compared_sweep(a), load_compared_sweep(b)])
    cheapest = min((r for r in other_rows if r.variant == "ankle+impulse"), key=lambda r: r.cost)
    assert (f"<td>ankle+impulse</td><td>{cheapest.speed_m_min:.1f}</td>"
            f"<td>{cheapest.step_length:.3f}</td><td>{cheapest.cost:.1f}</td>"
            "<td>cheapest solved speed</td>") in table
    assert f"<td>{np.sqrt(150.0):.1f}</td>" in table and "speed free" in table
    assert f"<td>{HUMAN_OPTIMAL_SPEED_M_MIN:.0f}</td><td>{HUMAN_STEP_LENGTH:.2f}</td>" in table


def test_report_command_compares(sweeps: tuple[Path, Path, list[SummaryRow]],
                                 tmp_path: Path) -> None:
    a, b, _ = sweeps
    runner = CliRunner()
    result = runner.invoke(cli, ["report", str(a), "-o", str(tmp_path / "cli"),
                                 "--compare", str(b)])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "cli" / "compare_sweeps.png").stat().st_size > 5000
    assert "Compared with other sweeps" in (tmp_path / "cli" / "report.html").read_text()
    assert "compared:" in result.output and "people: 80 m/min" in result.output
    bad = runner.invoke(cli, ["report", str(a), "--compare", str(tmp_path / "nothing")])
    assert bad.exit_code == 2 and "--compare" in bad.output and "no sweep" in bad.output
