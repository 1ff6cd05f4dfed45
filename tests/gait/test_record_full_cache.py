"""The full-coordinate gait record's phase functions (``qdd``, contact forces and the actuator
vector of a phase at its knots) are cached on disk: a second process loads them instead of
deriving the Contact Algorithm in symbols again, and the loaded function is the built one."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gaitopt.gait.formulations.full import extract as record_full
from gaitopt.gait.formulations.full import physics as full
from gaitopt.robot import load_model

HELD = ("tip_1", "tip_2:y")


@pytest.fixture
def fresh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """An empty disk cache and an empty process cache of the record's functions."""
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    record_full._phase_function.cache_clear()
    yield tmp_path
    record_full._phase_function.cache_clear()


def no_building(*args: Any, **kwargs: Any) -> None:
    raise AssertionError("built the record's phase function although it is cached")


def outputs(fn: Any, x: np.ndarray, u: np.ndarray) -> list[np.ndarray]:
    return [np.asarray(v, dtype=float) for v in fn(x, u)]


def test_the_record_function_is_loaded_from_the_disk_cache_and_equal(
        fresh: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    model = load_model("five-link")
    acts = full.actuator_names(model, HELD, ankle=True)
    built = record_full._phase_function(model, HELD, acts)
    files = list(fresh.glob("record-full-*.pickle"))
    assert len(files) == 1
    record_full._phase_function.cache_clear()  # a new process
    monkeypatch.setattr(record_full, "_build_phase_function", no_building)
    loaded = record_full._phase_function(model, HELD, acts)
    rng = np.random.default_rng(3)
    x = rng.normal(size=2 * model.nq)
    u = rng.normal(size=built.size1_in(1))
    for a, b in zip(outputs(built, x, u), outputs(loaded, x, u), strict=True):
        assert np.array_equal(a, b)
    # Independent of the cache: qdd and the forces are the Contact Algorithm's at that point.
    direct = full.phase_point(model, HELD, acts, x, u)
    qdd, forces, _ = outputs(loaded, x, u)
    assert np.allclose(qdd.ravel(), np.asarray(direct.qdd, dtype=float).ravel(), atol=1e-9)
    assert np.allclose(forces.ravel(), np.asarray(direct.forces, dtype=float).ravel(),
                       atol=1e-9)


def test_other_holds_or_actuators_or_a_corrupt_file_build_anew(fresh: Path) -> None:
    model = load_model("five-link")
    acts = full.actuator_names(model, HELD, ankle=True)
    path = record_full.phase_function_file(model, HELD, acts)
    assert record_full.phase_function_file(model, HELD[:1], acts) != path
    assert record_full.phase_function_file(
        model, HELD, full.actuator_names(model, HELD, ankle=False)) != path
    path.write_bytes(b"not a pickle")
    fn = record_full._phase_function(model, HELD, acts)
    assert fn.n_out() == 3
    assert path.read_bytes() != b"not a pickle"
