"""The ``gaitopt`` command line: one subcommand per step.

The group and the shared pieces (:class:`UserError`, :data:`USER_ERRORS`, the console) are in
:mod:`gaitopt.cli_base`; the subcommands in this module (``model``) and in
:mod:`gaitopt.cli_gait` (``solve``, ``verify``) and :mod:`gaitopt.cli_study` (``sweep``,
``report``, ``animate``, ``study``), which register on the group when imported here.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

import click
from rich import box
from rich.table import Table
from rich.text import Text

from gaitopt import cli_gait, cli_stability, cli_study  # noqa: F401  (they register their subcommands)
from gaitopt.cli_base import PIPE_WIDTH, USER_ERRORS, UserError, cli, make_console
from gaitopt.robot import RobotModel, builtin_names, builtin_text, load_model

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



__all__ = ["PIPE_WIDTH", "USER_ERRORS", "UserError", "cli", "main", "make_console", "model_tables"]

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
