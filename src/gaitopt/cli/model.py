"""``gaitopt model show``, ``export`` and ``import``: robot models (built-in, files, URDF)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import click
from rich import box
from rich.table import Table
from rich.text import Text

from gaitopt.cli.base import UserError, cli, make_console
from gaitopt.robot import RobotModel, builtin_names, builtin_text, load_model, model_to_yaml
from gaitopt.robot.symmetry import SymmetryError, model_symmetry

if TYPE_CHECKING:
    from gaitopt.robot.urdf import ContactSpec

# -- gaitopt model ---------------------------------------------------------------------------

@cli.group()
def model() -> None:
    """Show, export and import robot models (built-in models, model files, URDF)."""


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
    try:
        symmetry = model_symmetry(m).describe()
    except SymmetryError as exc:
        symmetry = f"none ({exc})"
    console.print(f"symmetry:      {symmetry}")


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
@click.argument("name_or_file")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="File to write; '-' for standard output (default: NAME.yaml or NAME.urdf "
                   "here).")
@click.option("--format", "fmt", type=click.Choice(["yaml", "urdf"]), default="yaml",
              show_default=True, help="yaml: a gaitopt model file; urdf: a URDF robot "
              "(docs/urdf.md).")
@click.option("--force", is_flag=True, help="Overwrite an existing file.")
def model_export(name_or_file: str, output: Path | None, fmt: str, force: bool) -> None:
    """Write a model (a built-in NAME or a model FILE) as a model file to edit or as URDF.

    A built-in model keeps its comments in YAML. Load the edited file with `gaitopt model
    show FILE` (and later commands' --model FILE); import a URDF with `gaitopt model import`.
    """
    m = load_model(name_or_file)  # a model that does not load fails before anything is written
    if fmt == "urdf":
        from gaitopt.robot.urdf import urdf_from_model

        text = urdf_from_model(m)
    else:
        text = builtin_text(name_or_file) if name_or_file in builtin_names() else model_to_yaml(m)
    _write_output(text, output, Path(f"{m.name}.{fmt}"), force)


def _write_output(text: str, output: Path | None, default: Path, force: bool) -> None:
    """Write ``text`` atomically to ``output`` (``-``: standard output; None: ``default``),
    refusing to replace an existing file without ``force``."""
    if output is not None and str(output) == "-":
        click.echo(text, nl=False)
        return
    out = output or default
    if out.exists() and not force:
        raise UserError(f"{out} exists; pass --force to overwrite it")
    from gaitopt.fileio import write_text_atomic

    try:
        write_text_atomic(out, text)
    except OSError as exc:
        raise UserError(f"{out}: cannot write the file ({exc.strerror or exc})") from None
    click.echo(f"wrote {out}")


@model.command("import")
@click.argument("urdf", metavar="FILE", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="Model file to write; '-' for standard output (default: the URDF's name "
                   "with .yaml, here).")
@click.option("--contact", "contacts", multiple=True, metavar="NAME=LINK:X,Z",
              help="Add a contact point NAME on URDF link (or MJCF body) LINK at (X, Z) m in "
                   "that link's frame (Y, Z with --axis x). Repeatable; contact frames that "
                   "gaitopt exported are read back without it; for MJCF it replaces the heel "
                   "and toe points inferred from the foot geoms.")
@click.option("--axis", type=click.Choice(["y", "x"]), default="y", show_default=True,
              help="The common joint axis: y (the sagittal plane is URDF x-z) or x (y-z).")
@click.option("--name", help="Model name (default: the URDF robot's name).")
@click.option("--force", is_flag=True, help="Overwrite an existing file.")
def model_import(urdf: Path, output: Path | None, contacts: tuple[str, ...], axis: str,
                 name: str | None, force: bool) -> None:
    """Read the planar robot in FILE (URDF, or MJCF: a .xml or <mujoco> file, compiled by
    MuJoCo) and write a gaitopt model file.

    Joints about the common axis become gaitopt joints (angles CCW about gaitopt z = URDF -y);
    fixed joints merge links; the root link, or the link after a planar, floating or
    prismatic-prismatic-revolute chain, is the floating base. Without --contact (or contact
    frames gaitopt exported), contacts are inferred from collision shapes on leaf links.
    Prints what it assumed: the base, the actuators, the contacts, the symmetry. See
    docs/urdf.md. In MJCF (docs/mjcf.md) the body with slide, slide and hinge joints is the
    base, bodies without joints merge, contacts come from the foot geoms and --contact gives
    X,Z in a body's frame.
    """
    from gaitopt.robot.mjcf import is_mjcf
    from gaitopt.robot.urdf import import_urdf, parse_contact_option

    try:
        specs = [parse_contact_option(c) for c in contacts]
    except ValueError as exc:
        raise UserError(str(exc)) from None
    if is_mjcf(urdf):
        _import_mjcf(urdf, output, specs, axis, name, force)
        return
    result = import_urdf(urdf, contacts=specs, axis=axis, name=name)
    m = result.model
    header = f"# imported by `gaitopt model import` from {urdf.name}\n"
    _write_output(header + model_to_yaml(m), output, Path(f"{urdf.stem}.yaml"), force)
    to_stderr = output is not None and str(output) == "-"  # keep the YAML on stdout clean
    click.echo(f"model {m.name}: {len(m.links)} links, {len(m.contacts)} contact points, "
               f"{m.nu} actuators, total mass {_g(m.total_mass)} kg", err=to_stderr)
    for line in result.lines():
        click.echo(line, err=to_stderr)


def _import_mjcf(path: Path, output: Path | None, specs: list[ContactSpec], axis: str,
                 name: str | None, force: bool) -> None:
    """``gaitopt model import`` of an MJCF file: the model file (what was assumed and dropped
    in its header comment), then the summary and those lines (on stderr with ``-o -``)."""
    from gaitopt.robot.mjcf import import_mjcf

    imp = import_mjcf(path, contacts=specs, axis=axis, name=name)
    m = imp.model
    header = (f"# imported by `gaitopt model import` from {path.name} (MJCF, compiled by "
              "MuJoCo)\n" + "".join(f"# {line}\n" for line in imp.notes))
    _write_output(header + model_to_yaml(m), output, Path(f"{path.stem}.yaml"), force)
    to_stderr = output is not None and str(output) == "-"
    click.echo(f"model {m.name}: {len(m.links)} links, {len(m.contacts)} contact points, "
               f"{m.nu} actuators, total mass {_g(m.total_mass)} kg", err=to_stderr)
    for line in imp.notes:
        click.echo(line, err=to_stderr)


__all__ = ["model", "model_tables"]
