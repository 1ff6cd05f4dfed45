"""``gaitopt model show|export`` through click's CliRunner (and one real process)."""

from __future__ import annotations

import contextlib
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from gaitopt.cli import PIPE_WIDTH, cli, main
from gaitopt.interrupts import Terminated, raise_terminated, terminated
from gaitopt.robot import load_model


@pytest.fixture
def runner() -> CliRunner:
    # pytest-xdist workers set COLUMNS=80; unset it to see what a plain pipe gets.
    return CliRunner(env={"COLUMNS": None})


def write_bad_model(folder: Path) -> Path:
    bad = folder / "bad.yaml"
    bad.write_text("name: bad\nlinks:\n  - {name: body, parent: null, direction: up, "
                   "length: 1.0, mass: -2.0, inertia: 1.0}\n")
    return bad


def test_show_five_link_prints_links_total_mass_and_inertias(runner: CliRunner) -> None:
    result = runner.invoke(cli, ["model", "show", "five-link"])
    assert result.exit_code == 0, result.output
    out = result.stdout
    lines = out.splitlines()
    model = load_model("five-link")
    for link in model.links:
        row = next(line for line in lines if line.split()[:1] == [link.name])
        # mass, length, centre of mass and inertia on the link's row
        assert f" {link.mass:g} " in row and f" {link.length:g} " in row
        assert f"({link.com[0]:g}, {link.com[1]:g})" in row
        assert f" {link.inertia:.6g} " in row
    assert {"0.576", "0.09436", "0.052"} <= set(out.split())
    total = next(line for line in lines if line.split()[:1] == ["total"])
    assert total.split()[1] == "42"
    for header in ("mass [kg]", "length [m]", "com [m]", "inertia [kg m^2]", "limits [rad]",
                   "limits [N m]"):
        assert header in out  # units are printed, not eaten as markup
    for name in ("hip_1", "knee_2", "tip_1", "ankle_2", "[-50, 50]", "[-25, 25]",
                 "[-2.5, 0]"):
        assert name in out
    assert "[x, y, torso, hip_1, knee_1, hip_2, knee_2]" in out


def test_show_output_is_readable_when_piped(runner: CliRunner) -> None:
    # CliRunner output is not a terminal: no colour codes, lines within PIPE_WIDTH, no cell
    # of the links table wrapped onto a second line (each link's row holds its inertia).
    out = runner.invoke(cli, ["model", "show"]).stdout
    assert "\x1b[" not in out
    assert max(len(line.rstrip()) for line in out.splitlines()) <= PIPE_WIDTH
    assert "…" not in out


def test_show_fits_80_columns(runner: CliRunner) -> None:
    narrow = CliRunner(env={"COLUMNS": "80"})
    out = narrow.invoke(cli, ["model", "show"]).stdout
    assert max(len(line.rstrip()) for line in out.splitlines()[:-2]) <= 80
    assert out.splitlines()[:-2] == runner.invoke(cli, ["model", "show"]).stdout.splitlines()[:-2]


def test_show_default_is_five_link(runner: CliRunner) -> None:
    assert runner.invoke(cli, ["model", "show"]).stdout == \
        runner.invoke(cli, ["model", "show", "five-link"]).stdout


def test_show_bad_file_exits_2_with_one_line(runner: CliRunner, tmp_path: Path) -> None:
    bad = write_bad_model(tmp_path)
    result = runner.invoke(cli, ["model", "show", str(bad)])
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.splitlines() == [
        f"Error: {bad}: links[0].mass: got -2.0; allowed: a number >= 0 (kg)"]
    assert "Traceback" not in result.output
    assert isinstance(result.exception, SystemExit)


def test_show_missing_file_and_bad_yaml_exit_2(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(cli, ["model", "show", str(tmp_path / "none.yaml")])
    assert result.exit_code == 2 and "no such file or built-in model" in result.stderr
    broken = tmp_path / "broken.yaml"
    broken.write_text("links: [1, 2\nname: x\n")
    result = runner.invoke(cli, ["model", "show", str(broken)])
    assert result.exit_code == 2
    assert len(result.stderr.splitlines()) == 1 and "not valid YAML" in result.stderr


def test_export_writes_a_file_that_loads_to_the_same_model(runner: CliRunner,
                                                           tmp_path: Path) -> None:
    out = tmp_path / "f.yaml"
    result = runner.invoke(cli, ["model", "export", "five-link", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert load_model(out) == load_model("five-link")
    assert out.read_text().startswith("# The five-link planar biped")  # comments kept


def test_export_refuses_to_overwrite_without_force(runner: CliRunner, tmp_path: Path) -> None:
    out = tmp_path / "f.yaml"
    out.write_text("my edits\n")
    result = runner.invoke(cli, ["model", "export", "five-link", "-o", str(out)])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [f"Error: {out} exists; pass --force to overwrite it"]
    assert out.read_text() == "my edits\n"
    result = runner.invoke(cli, ["model", "export", "five-link", "-o", str(out), "--force"])
    assert result.exit_code == 0, result.output
    assert load_model(out) == load_model("five-link")


def test_export_default_name_and_stdout(runner: CliRunner, tmp_path: Path,
                                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert runner.invoke(cli, ["model", "export", "five-link"]).exit_code == 0
    assert load_model(tmp_path / "five-link.yaml") == load_model("five-link")
    result = runner.invoke(cli, ["model", "export", "five-link", "-o", "-"])
    assert result.exit_code == 0
    copy = tmp_path / "from-stdout.yaml"
    copy.write_text(result.stdout)
    assert load_model(copy) == load_model("five-link")


def test_export_unknown_name_is_a_usage_error(runner: CliRunner) -> None:
    result = runner.invoke(cli, ["model", "export", "six-link"])
    assert result.exit_code == 2 and "five-link" in result.stderr
    assert "Traceback" not in result.output


def test_export_into_unwritable_place_is_a_user_error(runner: CliRunner,
                                                      tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    result = runner.invoke(cli, ["model", "export", "five-link", "-o",
                                 str(blocker / "sub" / "f.yaml")])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"Error: {blocker / 'sub' / 'f.yaml'}: cannot write")


def test_main_returns_exit_status(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["model", "show", "five-link"]) == 0
    raise_terminated_in_this_process()  # a SIGTERM of an earlier run is not this run's
    assert main(["model", "show", str(write_bad_model(tmp_path))]) == 2
    assert main(["--version"]) == 0
    assert "gaitopt" in capsys.readouterr().out


def raise_terminated_in_this_process() -> None:
    """What a SIGTERM noted in this process before (another test's) leaves behind."""
    with contextlib.suppress(Terminated):
        raise_terminated(signal.SIGTERM, None)
    assert terminated()


def test_real_process_prints_no_traceback(tmp_path: Path) -> None:
    bad = write_bad_model(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "gaitopt", "model", "show", str(bad)],
                          capture_output=True, text=True, timeout=120,
                          env={"PYTHONPATH": str(Path(__file__).parents[2] / "src"),
                               "PATH": "/usr/bin:/bin"})
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"Error: {bad}: links[0].mass: got -2.0; allowed: a number >= 0 (kg)"]
