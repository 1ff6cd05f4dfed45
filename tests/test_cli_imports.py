"""The command line imports a command's modules only when that command runs (issue 12: the
whole ``gaitopt solve`` process spent 0.7 s importing every command's modules, SciPy's
optimizer among them). Each check runs in a fresh interpreter, since this one has imported
everything already."""

from __future__ import annotations

import subprocess
import sys

from click.testing import CliRunner

from gaitopt.cli import COMMANDS, cli


def modules_after(code: str) -> set[str]:
    """The top-level and gaitopt modules loaded after running ``code`` in a fresh
    interpreter (this checkout's sources first on the path, as for the tests)."""
    out = subprocess.run(
        [sys.executable, "-c",
         f"{code}\nimport sys\nprint('\\n'.join(sorted(sys.modules)))"],
        capture_output=True, text=True, check=True).stdout
    return set(out.split())


def test_solve_loads_neither_the_study_nor_scipy_nor_matplotlib() -> None:
    loaded = modules_after(
        "from gaitopt.cli import cli\n"
        "import click\n"
        "ctx = click.Context(cli)\n"
        "assert cli.get_command(ctx, 'solve') is not None")
    assert "gaitopt.cli.gait" in loaded and "casadi" in loaded  # the command is there
    for unwanted in ("gaitopt.cli.study", "gaitopt.cli.report", "gaitopt.cli.stability",
                     "gaitopt.cli.model", "gaitopt.study.driver", "scipy.optimize",
                     "matplotlib", "gaitopt.viz"):
        assert unwanted not in loaded, unwanted


def test_importing_the_cli_loads_no_command_and_no_rich() -> None:
    loaded = modules_after("import gaitopt.cli")
    assert not {m for m in loaded if m.split(".")[0] == "rich"}
    assert not {f"gaitopt.cli.{m}" for m in ("gait", "study", "report", "stability",
                                               "model")} & loaded


def test_every_command_is_listed_and_found() -> None:
    """``gaitopt --help`` lists every command of :data:`COMMANDS` and each one resolves to a
    command registered by its module."""
    result = CliRunner().invoke(cli, ["--help"])
    assert result.exit_code == 0
    listed = [line.split()[0] for line in result.output.split("Commands:")[1].splitlines()
              if line.strip()]
    assert listed == sorted(COMMANDS)
    for name in COMMANDS:
        assert CliRunner().invoke(cli, [name, "--help"]).exit_code == 0, name


def test_an_unknown_command_is_a_usage_error() -> None:
    result = CliRunner().invoke(cli, ["solv"])
    assert result.exit_code == 2 and "No such command 'solv'" in result.output

