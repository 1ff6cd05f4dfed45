"""Model files: reading YAML model files and the built-in models, writing models as YAML.

The schema and its validation are in :mod:`gaitopt.robot.schema` (and ``docs/conventions.md``);
this module only touches text and files. Every problem is a :class:`ModelError` whose one-line
message names the file, the field path, the bad value and what is allowed.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from gaitopt.robot.errors import ModelError
from gaitopt.robot.inertia import ellipsoid_inertia, rod_inertia
from gaitopt.robot.model import FORMAT, VERSION, RobotModel, model_to_dict
from gaitopt.robot.schema import model_from_dict

__all__ = [
    "FORMAT", "VERSION", "ModelError", "builtin_names", "builtin_text", "ellipsoid_inertia",
    "load_model", "model_from_dict", "model_from_yaml", "model_to_dict", "model_to_yaml",
    "rod_inertia",
]

_BUILTIN = ("gaitopt.robot", "builtin")


def builtin_names() -> list[str]:
    """Names of the models shipped with gaitopt (``five-link``), sorted."""
    folder = resources.files(_BUILTIN[0]) / _BUILTIN[1]
    return sorted(p.name.removesuffix(".yaml") for p in folder.iterdir()
                  if p.name.endswith(".yaml"))


def builtin_text(name: str) -> str:
    """The YAML text (with its comments) of the built-in model ``name``."""
    names = builtin_names()
    if name not in names:
        raise ModelError(name, "", name, f"a built-in model name ({', '.join(names)})",
                         problem="no such built-in model")
    return (resources.files(_BUILTIN[0]) / _BUILTIN[1] / f"{name}.yaml").read_text("utf-8")


def load_model(name_or_path: str | os.PathLike[str]) -> RobotModel:
    """Load a built-in model by name (``five-link``) or a model file by path.

    A built-in name takes precedence; write ``./five-link`` to load a file of that name.
    """
    text_name = os.fspath(name_or_path)
    names = builtin_names()
    if text_name in names:
        return model_from_yaml(builtin_text(text_name), source=f"<builtin {text_name}>")
    allowed = f"a model file (YAML) or a built-in model name ({', '.join(names)})"
    path = Path(text_name)
    if not path.exists():
        raise ModelError(text_name, "", text_name, allowed,
                         problem="no such file or built-in model")
    if not path.is_file():
        raise ModelError(text_name, "", text_name, allowed, problem="not a file")
    try:
        text = path.read_bytes().decode("utf-8")
    except OSError as exc:
        raise ModelError(text_name, "", text_name, allowed,
                         problem=f"cannot be read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise ModelError(text_name, "", f"byte {exc.start}", "a UTF-8 text file (YAML)",
                         problem=f"not UTF-8 text at byte {exc.start}") from None
    return model_from_yaml(text, source=text_name)


def model_from_yaml(text: str, *, source: str = "<string>") -> RobotModel:
    """Parse and validate YAML model text; ``source`` names it in errors."""
    return model_from_dict(parse_yaml(text, source=source), source=source)


def parse_yaml(text: str, *, source: str = "<string>") -> Any:
    """``yaml.safe_load`` that reports any failure as a one-line :class:`ModelError`."""
    try:
        return yaml.safe_load(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = " ".join(str(exc.problem or exc.context or "unreadable").split())
        raise ModelError(source, where, MISSING_YAML, "well-formed YAML",
                         problem=f"not valid YAML: {problem}") from None
    except Exception as exc:  # e.g. an impossible date (ValueError), deep nesting
        detail = " ".join(str(exc).split()) or type(exc).__name__
        raise ModelError(source, "", MISSING_YAML, "well-formed YAML",
                         problem=f"not valid YAML: {detail}") from None


#: Placeholder value of YAML syntax errors (the bad text is in the message).
MISSING_YAML = "(YAML text)"


def model_to_yaml(model: RobotModel) -> str:
    """The model as model-file YAML text; ``model_from_yaml(model_to_yaml(m)) == m``."""
    header = (f"# gaitopt model file ({FORMAT} version {VERSION}); the schema is in "
              "docs/conventions.md\n")
    return header + yaml.safe_dump(model_to_dict(model), sort_keys=False,
                                   default_flow_style=None, allow_unicode=True, width=100)
