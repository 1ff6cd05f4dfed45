"""``from gaitopt import ...``: the public names, imported lazily."""

from __future__ import annotations

import subprocess
import sys

import pytest

import gaitopt


def test_the_public_names_are_the_exports() -> None:
    assert set(gaitopt.__all__) == set(gaitopt._EXPORTS) | {"__version__"}


@pytest.mark.parametrize("name", sorted(gaitopt._EXPORTS))
def test_each_public_name_is_the_defining_modules_object(name: str) -> None:
    import importlib

    module = importlib.import_module(gaitopt._EXPORTS[name])
    assert getattr(gaitopt, name) is getattr(module, name)


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no attribute 'solve'"):
        gaitopt.solve  # noqa: B018


def test_import_gaitopt_loads_neither_casadi_nor_scipy() -> None:
    code = ("import sys, gaitopt; from gaitopt import GaitOptions, load_model; "
            "print(sorted(m for m in ('casadi', 'scipy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
