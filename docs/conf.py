"""Sphinx configuration of the gaitopt documentation (``make docs``).

The Markdown pages in this folder are read by myst-parser; the API reference (``api.md``) is
generated from the docstrings by autodoc (Google style, read by napoleon) and the command-line
reference (``cli.md``) from the click commands by sphinx-click. The build treats warnings as
errors (``sphinx-build -W``).
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from gaitopt import __version__  # noqa: E402

project = "gaitopt"
author = "the gaitopt authors"
copyright = "the gaitopt authors"
version = release = __version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx_click",
]

root_doc = "index"
source_suffix = {".md": "markdown"}
exclude_patterns = ["_build"]

# Markdown: headings down to level 4 get anchors, so that links like
# `walking.md#6-grid-convergence-the-control-model-and-swing-clearance` resolve (GitHub's slugs,
# the form the pages use and GitHub shows). No math extension: `$` is plain text.
myst_heading_anchors = 4

# The docstrings are Google style (Args:, Returns:, Raises:, Attributes:).
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_attr_annotations = True
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"members": True}

html_theme = "alabaster"
html_title = f"gaitopt {__version__}"
html_static_path: list[str] = []

# Register every command family on the `gaitopt` group (they are imported lazily when a
# command is looked up), so sphinx-click documents each command and every option.
from gaitopt.cli import COMMANDS  # noqa: E402

for _module in sorted(set(COMMANDS.values())):
    importlib.import_module(_module)
