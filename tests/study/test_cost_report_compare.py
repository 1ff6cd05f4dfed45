"""``gaitopt report STUDY --compare OTHER`` for cost studies: the models of two studies (for
example one solved on 8 + 5 knots, one with feet on 24 + 16) in one figure, table and set of
findings."""

from __future__ import annotations

import math
from pathlib import Path

from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.robot import load_model
from gaitopt.study.cost_study import CostStudySpec, write_settings
from gaitopt.study.cost_table import CostRow, write_cost_table
from gaitopt.viz.cost_report import study_rows, write_cost_report


def _row(model: str, case: str, speed: float, step: float) -> CostRow:
    rest = float(case.rsplit("-", 1)[1]) if case.startswith("metabolic") else math.nan
    return CostRow(model=model, formulation="reduced", case=case,
                   cost="metabolic" if case.startswith("metabolic") else case,
                   resting_power=rest, success=True, status="Solve_Succeeded",
                   speed_m_min=speed, step_length=step, step_time=step / (speed / 60.0),
                   cost_value=1.0, file="")


def _study(path: Path, rows: list[CostRow]) -> Path:
    write_settings(CostStudySpec(models=(load_model("five-link"),)), path)
    write_cost_table(path, rows)
    return path


def test_compared_studies_share_the_report(tmp_path: Path) -> None:
    """The compared study's models join the figure's legend, the table and the findings; the
    study's own rows come first."""
    one = _study(tmp_path / "one", [_row("five-link", "paper", 11.1, 0.107),
                                    _row("five-link", "metabolic-rest-1.2", 27.1, 0.33)])
    two = _study(tmp_path / "two", [_row("feet", "paper", 74.8, 0.70),
                                    _row("feet", "metabolic-rest-1.2", 62.5, 0.55)])
    rows = study_rows(one, [two])
    assert [r.model for r in rows] == ["five-link", "five-link", "feet", "feet"]
    info = write_cost_report(one, tmp_path / "report", compare=[two], svg=True)
    assert set(info.findings) == {"five-link", "feet"}
    page = info.html.read_text()
    assert ">62.5<" in page and ">27.1<" in page
    assert page.index(">62.5<") < page.index(">27.1<")  # nearest to people's walk first
    svg = next(p for p in info.figures if p.suffix == ".svg").read_text()
    assert "feet (reduced): metabolic cost" in svg and "five-link (reduced)" in svg


def test_cli_compare_of_cost_studies(tmp_path: Path) -> None:
    """On the command line; a model in both studies, or a compared folder that is not a cost
    study, is a usage error that names it, and no report is written."""
    one = _study(tmp_path / "one", [_row("five-link", "paper", 11.1, 0.107)])
    two = _study(tmp_path / "two", [_row("feet", "paper", 74.8, 0.70)])
    result = CliRunner().invoke(cli, ["report", str(one), "--compare", str(two)])
    assert result.exit_code == 0, result.output
    assert "feet" in result.output and "five-link" in result.output
    assert (one / "report" / "report.html").exists()

    same = _study(tmp_path / "same", [_row("five-link", "paper", 12.0, 0.11)])
    result = CliRunner().invoke(cli, ["report", str(two), "--compare", str(same), "-o",
                                      str(tmp_path / "r2")])
    assert result.exit_code == 0, result.output
    result = CliRunner().invoke(cli, ["report", str(one), "--compare", str(same), "-o",
                                      str(tmp_path / "r3")])
    assert result.exit_code == 2
    assert "five-link" in result.output and "two of the compared" in " ".join(
        result.output.split())
    assert not (tmp_path / "r3" / "report.html").exists()

    plain = tmp_path / "plain"
    plain.mkdir()
    result = CliRunner().invoke(cli, ["report", str(one), "--compare", str(plain), "-o",
                                      str(tmp_path / "r4")])
    assert result.exit_code == 2
    assert "no cost study here" in " ".join(result.output.split())
    assert not (tmp_path / "r4" / "report.html").exists()
