"""The multibody functions are cached on disk (:mod:`gaitopt.dynamics.function_cache`): a new
process loads them instead of tracing the algorithms again, gets the same function, and a
changed model or a corrupt file builds anew."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from gaitopt.dynamics import function_cache
from gaitopt.dynamics import functions as dynamics_functions
from gaitopt.robot import load_model
from gaitopt.robot.loader import builtin_text
from gaitopt.robot.schema import model_from_dict


@pytest.fixture
def fresh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty disk cache and an empty process cache (restored afterwards)."""
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    monkeypatch.setattr(dynamics_functions, "_CACHE", {})
    return tmp_path


def no_tracing(*args: Any, **kwargs: Any) -> None:
    raise AssertionError("traced the contact dynamics although they are cached")


def values(f: Any, nq: int, nu: int) -> list[np.ndarray]:
    rng = np.random.default_rng(5)
    q, qd, u = rng.normal(size=nq), rng.normal(size=nq), rng.normal(size=nu)
    return [np.asarray(v, dtype=float) for v in f(q, qd, u)]


def test_a_new_process_loads_the_same_function(fresh: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    model = load_model("seven-link")
    contacts = ("heel_1", "toe_1")
    built = dynamics_functions.contact_dynamics_function(model, contacts, inputs="u")
    assert len(list(fresh.glob("dynamics-*.pickle"))) == 1
    # A new process: nothing in memory, and tracing the algorithms would fail.
    monkeypatch.setattr(dynamics_functions, "_CACHE", {})
    monkeypatch.setattr(dynamics_functions, "contact_dynamics_scalars", no_tracing)
    loaded = dynamics_functions.contact_dynamics_function(model, contacts, inputs="u")
    assert loaded is not built
    assert loaded.name() == built.name()
    for a, b in zip(values(loaded, model.nq, model.nu), values(built, model.nq, model.nu),
                    strict=True):
        np.testing.assert_array_equal(a, b)


def test_a_changed_model_or_a_corrupt_file_builds_anew(fresh: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    model = load_model("five-link")
    dynamics_functions.contact_dynamics_function(model, ("tip_1",), inputs="u")
    (path,) = fresh.glob("dynamics-*.pickle")
    data = yaml.safe_load(builtin_text("five-link"))
    data["links"][2]["mass"] = 4.5
    heavier = model_from_dict(data)
    dynamics_functions.contact_dynamics_function(heavier, ("tip_1",), inputs="u")
    assert len(list(fresh.glob("dynamics-*.pickle"))) == 2
    path.write_bytes(b"not a pickle")
    monkeypatch.setattr(dynamics_functions, "_CACHE", {})
    f = dynamics_functions.contact_dynamics_function(model, ("tip_1",), inputs="u")
    assert function_cache.cached_functions(path) is not None        # replaced
    assert all(np.all(np.isfinite(v)) for v in values(f, model.nq, model.nu))
