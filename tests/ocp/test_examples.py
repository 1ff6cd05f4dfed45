"""The ocp example scripts run and reproduce their analytic answers."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_brachistochrone_example(tmp_path: Path) -> None:
    png = tmp_path / "b.png"
    rel = load("ocp_brachistochrone").main(["--intervals", "10", "--tol", "1e-7",
                                             "--plot", str(png)])
    assert rel < 1e-5
    assert png.stat().st_size > 1000


def test_periodic_cart_example() -> None:
    assert load("ocp_periodic_cart").main(["--intervals", "4"]) < 1e-7
