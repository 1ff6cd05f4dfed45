"""The documentation site (``make docs``): its configuration loads, the API page names every
public name, the results pages are listed, and the command-line reference documents every
option of every command (built here on its own, as text, without the other pages)."""

from __future__ import annotations

import runpy
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import click
import pytest

import gaitopt

DOCS = Path(__file__).resolve().parent.parent / "docs"


def test_the_sphinx_configuration_loads() -> None:
    conf = runpy.run_path(str(DOCS / "conf.py"))
    assert {"myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon",
            "sphinx_click"} <= set(conf["extensions"])
    assert conf["root_doc"] == "index"
    assert conf["myst_heading_anchors"] >= 3  # links like walking.md#6-grid-convergence...


def test_the_api_page_documents_every_public_name() -> None:
    text = (DOCS / "api.md").read_text(encoding="utf-8")
    for name in ("solve_gait", "GaitOptions", "Gait", "load_model", "verify_gait",
                 *gaitopt._EXPORTS):
        assert f":: gaitopt.{name}\n" in text, name


def test_every_results_page_is_listed() -> None:
    index = (DOCS / "results" / "index.md").read_text(encoding="utf-8")
    pages = sorted(p.stem for p in (DOCS / "results").glob("*.md") if p.stem != "index")
    assert pages
    for page in pages:
        assert f"\n{page}\n" in index, page  # in the toctree
        assert f"({page}.md)" in index, page  # and in the list


def _commands(group: click.Group, path: tuple[str, ...] = ("gaitopt",)
              ) -> Iterator[tuple[tuple[str, ...], click.Command]]:
    ctx = click.Context(group)
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        assert command is not None, name
        yield (*path, name), command
        if isinstance(command, click.Group):
            yield from _commands(command, (*path, name))


def test_the_cli_reference_documents_every_option(tmp_path: Path) -> None:
    pytest.importorskip("sphinx_click")
    from gaitopt.cli import cli

    source = tmp_path / "source"
    source.mkdir()
    (source / "index.md").write_text((DOCS / "cli.md").read_text(encoding="utf-8"),
                                     encoding="utf-8")
    out = tmp_path / "text"
    subprocess.run([sys.executable, "-m", "sphinx", "-q", "-b", "text", "-c", str(DOCS),
                    str(source), str(out)], check=True, capture_output=True, text=True)
    text = (out / "index.txt").read_text(encoding="utf-8")

    commands = list(_commands(cli))
    assert len(commands) >= 10
    for path, command in commands:
        assert " ".join(path) in text, path
        for param in command.params:
            if isinstance(param, click.Option):
                for opt in (*param.opts, *param.secondary_opts):
                    assert opt in text, (path, opt)
            elif isinstance(param, click.Argument):
                assert (param.name or "").upper() in text, (path, param.name)
