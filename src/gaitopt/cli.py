"""The ``gaitopt`` command line: one subcommand per step.

Errors the user can fix (a bad model file, a bad option) are printed as one clear message and
exit with status 2; they never show a traceback.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

import click
from rich.console import Console
from rich.table import Table

from gaitopt import __version__
from gaitopt.robot import ModelError, load_model, model_to_yaml
from gaitopt.robot.loader import builtin_names

console = Console()


class UserError(click.ClickException):
    """An error in what the user asked for: printed as one message, exit status 2."""

    exit_code = 2


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="gaitopt")
def cli() -> None:
    """gaitopt: energy-optimal walking gaits for planar multibody bipeds."""


@cli.group()
def model() -> None:
    """Show and export robot models."""


@model.command("show")
@click.argument("name_or_file", default="five-link")
def model_show(name_or_file: str) -> None:
    """Print the links, contacts and actuators of a built-in model or a model file."""
    try:
        m = load_model(name_or_file)
    except ModelError as exc:
        raise UserError(str(exc)) from None
    table = Table(title=f"model {m.name}  ({m.nq} coordinates, {m.nu} actuators)")
    for col in ("link", "parent", "joint", "mass [kg]", "length [m]", "com [m]",
                "inertia [kg m²]", "joint limits [rad]"):
        table.add_column(col, justify="right" if "[" in col else "left")
    for link in m.links:
        joint = link.joint
        table.add_row(
            link.name, link.parent or "(floating base)", joint.name if joint else "-",
            f"{link.mass:g}", f"{link.length:g}", f"({link.com[0]:g}, {link.com[1]:g})",
            f"{link.inertia:.5g}",
            f"[{joint.limits[0]:g}, {joint.limits[1]:g}]" if joint else "-",
        )
    table.add_section()
    table.add_row("total", "", "", f"{m.total_mass:g}", "", "", "", "")
    console.print(table)
    contacts = Table(title="contact points")
    for col in ("contact", "link", "at [m]"):
        contacts.add_column(col)
    for c in m.contacts:
        contacts.add_row(c.name, c.link, f"({c.at[0]:g}, {c.at[1]:g})")
    console.print(contacts)
    actuators = Table(title="actuators (controls u, in order)")
    for col in ("actuator", "acts on", "limits [N m]"):
        actuators.add_column(col)
    for a in m.actuators:
        target = f"joint {a.joint}" if a.joint else f"contact {a.contact} (ground torque)"
        actuators.add_row(a.name, target, f"[{a.limits[0]:g}, {a.limits[1]:g}]")
    console.print(actuators)
    console.print(f"gravity: ({m.gravity[0]:g}, {m.gravity[1]:g}) m/s²")


@model.command("export")
@click.argument("name", type=click.Choice(builtin_names()))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="File to write (default: NAME.yaml in the current folder).")
@click.option("--force", is_flag=True, help="Overwrite an existing file.")
def model_export(name: str, output: Path | None, force: bool) -> None:
    """Write a built-in model as a model file to edit."""
    from gaitopt.robot.loader import builtin_text

    out = output or Path(f"{name}.yaml")
    if out.exists() and not force:
        raise UserError(f"{out} exists; pass --force to overwrite it")
    text = builtin_text(name)
    # Validate the round trip before writing so an exported file always loads.
    load_model(name)
    _write_atomic(out, text)
    console.print(f"wrote {out}")


def _write_atomic(path: Path, text: str) -> None:
    from gaitopt.fileio import write_text_atomic

    write_text_atomic(path, text)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gaitopt`` console script."""
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="gaitopt",
                 standalone_mode=True)
    except SystemExit as exc:
        return int(exc.code or 0) if not isinstance(exc.code, str) else 1
    return 0


__all__ = ["cli", "main", "model_to_yaml"]

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
