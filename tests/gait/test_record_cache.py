"""The reduced gait record's phase functions (``q, qd, qdd``, contact forces, the actuator
vector and ``xdot`` of a phase at its knots) are cached on disk like the full-coordinate
ones: a second process loads them instead of deriving the Contact Algorithm in symbols
again, the loaded function equals the built one, and a changed model builds anew."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gaitopt.gait import record_reduced as record
from gaitopt.gait import walking
from gaitopt.gait.walking import DOUBLE, SINGLE
from gaitopt.robot import load_model


@pytest.fixture
def fresh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """An empty disk cache and an empty process cache of the record's functions."""
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    record._phase_functions.cache_clear()
    yield tmp_path
    record._phase_functions.cache_clear()


def no_building(*args: Any, **kwargs: Any) -> None:
    raise AssertionError("built the record's phase function although it is cached")


@pytest.mark.parametrize("phase", [SINGLE, DOUBLE])
def test_the_reduced_record_function_is_loaded_from_the_disk_cache_and_equal(
        fresh: Path, monkeypatch: pytest.MonkeyPatch, phase: str) -> None:
    model = load_model("five-link")
    controls = walking.control_names(model, phase, ankle=True)
    built = record._phase_functions(model, phase, controls)
    assert len(list(fresh.glob("record-reduced-1-*.pickle"))) == 1
    record._phase_functions.cache_clear()  # a new process
    monkeypatch.setattr(record, "_build_phase_functions", no_building)
    loaded = record._phase_functions(model, phase, controls)
    rng = np.random.default_rng(5)
    x = rng.normal(scale=0.3, size=built.size1_in(0))
    u = rng.normal(size=built.size1_in(1))
    for a, b in zip(built(x, u, 0.4), loaded(x, u, 0.4), strict=True):
        assert np.array_equal(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    # Independent of the cache: xdot is the walking problem's own point function's.
    point = (walking.single_support_point(model, x, u, controls) if phase == SINGLE else
             walking.double_support_point(model, x, u, controls, 0.4))
    assert np.allclose(np.asarray(loaded(x, u, 0.4)[5], dtype=float).ravel(),
                       np.asarray(point.xdot, dtype=float).ravel(), atol=1e-9)


def test_another_model_or_phase_builds_anew(fresh: Path) -> None:
    model = load_model("five-link")
    controls = walking.control_names(model, SINGLE, ankle=True)
    record._phase_functions(model, SINGLE, controls)
    heavier = dataclasses.replace(
        model, links=(dataclasses.replace(model.links[0], mass=model.links[0].mass * 1.1),
                      *model.links[1:]))
    record._phase_functions(heavier, SINGLE, controls)
    record._phase_functions(model, SINGLE, walking.control_names(model, SINGLE, ankle=False))
    assert len(list(fresh.glob("record-reduced-1-*.pickle"))) == 3
