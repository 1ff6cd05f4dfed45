"""The ``gaitopt`` command line: one subcommand per step.

Errors the user can fix (a bad model file, a bad option) are printed as one clear line
(``Error: ...``) on stderr and exit with status 2; they never show a traceback. A subcommand
signals one by raising :class:`UserError`, or any exception type listed in
:data:`USER_ERRORS` (converted by the ``cli`` group), e.g. :class:`~gaitopt.robot.ModelError`.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click
from rich import box
from rich.console import Console
from rich.table import Table
from rich.text import Text

from gaitopt import __version__
from gaitopt.robot import ModelError, RobotModel, builtin_names, builtin_text, load_model

#: Exception types that are the user's to fix: shown as one line, exit status 2.
USER_ERRORS: tuple[type[Exception], ...] = (ModelError,)

#: Width of tables when the output is not a terminal (a pipe, a file, a CI log).
PIPE_WIDTH = 120


class UserError(click.ClickException):
    """An error in what the user asked for: printed as one message, exit status 2."""

    exit_code = 2

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(message.split()))


class _Group(click.Group):
    """A click group that turns :data:`USER_ERRORS` into :class:`UserError`."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except USER_ERRORS as exc:
            raise UserError(str(exc)) from None


def make_console() -> Console:
    """A rich console on stdout; at least :data:`PIPE_WIDTH` columns when not a terminal
    (unless ``COLUMNS`` says otherwise), so piped tables are not squeezed to 80 columns.

    Markup is off: text such as ``[kg]`` or ``[-2, 2]`` is printed as it is.
    """
    console = Console(markup=False, highlight=False)
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(markup=False, highlight=False, width=max(console.width, PIPE_WIDTH))
    return console


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="gaitopt")
def cli() -> None:
    """gaitopt: energy-optimal walking gaits for planar multibody bipeds."""


# -- gaitopt model ---------------------------------------------------------------------------

@cli.group()
def model() -> None:
    """Show and export robot models (built-in models or model files)."""


@model.command("show")
@click.argument("name_or_file", default="five-link")
def model_show(name_or_file: str) -> None:
    """Print the links, joints, contact points and actuators of a model.

    NAME_OR_FILE is a built-in model name (default: five-link) or a model file (YAML).
    """
    m = load_model(name_or_file)
    console = make_console()
    for table in model_tables(m):
        console.print(table)
    console.print(f"gravity [m/s^2]: ({_g(m.gravity[0])}, {_g(m.gravity[1])})")
    console.print(f"coordinates q: [{', '.join(m.coordinate_names)}]")
    console.print(f"controls u:    [{', '.join(a.name for a in m.actuators)}]")


def model_tables(m: RobotModel) -> list[Table]:
    """The tables of ``gaitopt model show``: links (with the total mass), joints, contact
    points and actuators. Points are ``(along, across)`` in m on the link (see the docs)."""
    def table(title: str, *columns: str) -> Table:
        t = Table(title=Text(title, style="bold"), title_justify="left", box=box.SIMPLE_HEAD,
                  pad_edge=False, collapse_padding=True)
        for col in columns:
            numeric = col.split(" [")[0] in ("mass", "length", "inertia")
            t.add_column(Text(col), justify="right" if numeric else "left")
        return t

    links = table(f"model {m.name}: {len(m.links)} links, {m.nq} coordinates, "
                  f"{m.nu} actuators", "link", "mass [kg]", "length [m]", "com [m]",
                  "inertia [kg m^2]", "shape")
    for link in m.links:
        shape = "-"
        if link.shape is not None:
            shape = (f"ellipsoid r={_g(link.shape.radius)}" if link.shape.radius is not None
                     else link.shape.type)
        links.add_row(link.name, _g(link.mass), _g(link.length), _pair(link.com),
                      _g(link.inertia), shape)
    links.add_section()
    links.add_row("total", _g(m.total_mass), "", "", "", "")

    joints = table(f"joints (the floating base is {m.base.name})", "joint", "parent -> link",
                   "at [m] on parent", "limits [rad]")
    for link in m.links:
        if link.joint is not None:
            joints.add_row(link.joint.name, f"{link.parent} -> {link.name}",
                           _pair(link.joint.at), _bounds(link.joint.limits))

    contacts = table("contact points", "contact", "link", "at [m] on link")
    for c in m.contacts:
        contacts.add_row(c.name, c.link, _pair(c.at))

    actuators = table("actuators (the controls u, in order)", "actuator", "acts on",
                      "limits [N m]")
    for a in m.actuators:
        target = f"joint {a.joint}" if a.joint else f"contact {a.contact} (ground torque)"
        actuators.add_row(a.name, target, _bounds(a.limits))
    return [links, joints, contacts, actuators]


def _g(x: float | None) -> str:
    return "-" if x is None else f"{x:.6g}"


def _pair(p: tuple[float, float]) -> str:
    return f"({_g(p[0])}, {_g(p[1])})"


def _bounds(b: tuple[float, float]) -> str:
    return f"[{_g(b[0])}, {_g(b[1])}]"


@model.command("export")
@click.argument("name", type=click.Choice(builtin_names()))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="File to write; '-' for standard output (default: NAME.yaml here).")
@click.option("--force", is_flag=True, help="Overwrite an existing file.")
def model_export(name: str, output: Path | None, force: bool) -> None:
    """Write the built-in model NAME as a model file to edit (with its comments).

    Load the edited file with `gaitopt model show FILE` (and later commands' --model FILE).
    """
    text = builtin_text(name)
    load_model(name)  # a built-in model that does not load is a bug: fail before writing
    if output is not None and str(output) == "-":
        click.echo(text, nl=False)
        return
    out = output or Path(f"{name}.yaml")
    if out.exists() and not force:
        raise UserError(f"{out} exists; pass --force to overwrite it")
    from gaitopt.fileio import write_text_atomic

    try:
        write_text_atomic(out, text)
    except OSError as exc:
        raise UserError(f"{out}: cannot write the file ({exc.strerror or exc})") from None
    click.echo(f"wrote {out}")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gaitopt`` console script; returns the exit status."""
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="gaitopt",
                 standalone_mode=True)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return 0


# Subcommands defined in their own modules register themselves on ``cli`` when imported.
from gaitopt import cli_gait  # noqa: E402,F401,I001  (imported for its side effect)
from gaitopt import cli_study  # noqa: E402,F401,I001  (imported for its side effect)

__all__ = ["USER_ERRORS", "UserError", "cli", "main", "make_console", "model_tables"]

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
