"""``gaitopt solve --mesh-tol/--control-model/--clearance``: bad values are one-line usage
errors (exit 2) naming the field and its range, before any solve; good ones reach the gait
file and the summary."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.record.file import Gait
from gaitopt.robot import load_model
from gaitopt.robot.biped import biped_of


@pytest.mark.parametrize(("args", "field", "allowed"), [
    (("--mesh-tol", "-1e-3"), "mesh_tol", "(0, 1)"),
    (("--mesh-tol", "0"), "mesh_tol", "(0, 1)"),
    (("--clearance", "-0.01"), "swing_clearance", "[0, 0.999)"),
    (("--clearance", "1.5"), "swing_clearance", "[0, 0.999)"),
])
def test_bad_values_are_one_line_usage_errors(args: tuple[str, ...], field: str,
                                              allowed: str) -> None:
    result = CliRunner().invoke(cli, ["solve", *args])
    assert result.exit_code == 2
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and field in lines[0] and allowed in lines[0], result.output
    assert "stage" not in result.output  # refused before solving


def test_an_unknown_control_model_is_refused() -> None:
    result = CliRunner().invoke(cli, ["solve", "--control-model", "smooth"])
    assert result.exit_code == 2 and "smooth" in result.output
    with pytest.raises(GaitOptionsError, match=r"control_model = 'smooth': must be one of"):
        validate_options(GaitOptions.paper(control_model="smooth"),  # type: ignore[arg-type]
                         biped_of(load_model("five-link")))
    with pytest.raises(GaitOptionsError, match=r"clearance_profile = 'sine'"):
        validate_options(GaitOptions.paper(swing_clearance=0.01,
                                     clearance_profile="sine"),  # type: ignore[arg-type]
                         biped_of(load_model("five-link")))


def test_the_options_reach_the_gait_file_and_the_summary(tmp_path: Path) -> None:
    out = tmp_path / "jumps.gait.json"
    result = CliRunner(env={"COLUMNS": "200"}).invoke(cli, ["solve", "--control-model", "jumps",
                                                            "--knots", "8,5", "--clearance",
                                      "0.01", "-o", str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "collocation error (largest per interval)" in text
    # cosine-spaced 8 + 5 knots (the default spacing) checked on 16 + 6 (factor 16 / 8)
    assert "cost error estimate" in text and "2 x the change to 16+6 knots" in text
    options = Gait.load(out).options
    assert options["control_model"] == "jumps" and options["swing_clearance"] == 0.01
    assert options["clearance_profile"] == "quartic" and options["mesh_tol"] is None
