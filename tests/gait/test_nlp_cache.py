"""The walking solve's NLP caches: the symbolic functions of a problem are shared between its
grids in a process and cached on disk (keyed by the model, the shaping options and the
sources), and the transcription built from them is the same NLP."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import gaitopt.ocp.transcription as transcription_module
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve import staged as gait_solve
from gaitopt.gait.solve import transcriptions
from gaitopt.robot import load_model
from gaitopt.robot.loader import builtin_text
from gaitopt.robot.schema import model_from_dict

# The compressed form: its transcription compiles nothing (the separated one would compile its
# point libraries into each test's empty cache).
OPTIONS = GaitOptions.paper(speed=0.2, knots=(4, 3), transcription="hermite-simpson")


@pytest.fixture
def fresh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty disk cache and an empty process cache (restored afterwards)."""
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    monkeypatch.setattr(transcriptions, "_CACHE", {})
    return tmp_path


def no_building(*args: Any, **kwargs: Any) -> None:
    raise AssertionError("built the phase functions although they are cached")


def evaluate(tr: Any) -> list[np.ndarray]:
    w = tr.initial_guess()
    return [np.asarray(v, dtype=float) for v in tr.nlp.evaluate(w)]


def test_functions_come_from_the_disk_cache_and_give_the_same_nlp(
        fresh: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    model = load_model("five-link")
    built = transcriptions.transcription_for(model, OPTIONS, OPTIONS.knots)
    files = list(fresh.glob("walking-functions-*.pickle"))
    assert len(files) == 1
    # A new process (empty process cache) loads them instead of building them.
    monkeypatch.setattr(transcriptions, "_CACHE", {})
    monkeypatch.setattr(transcription_module, "build_phase_function", no_building)
    loaded = transcriptions.transcription_for(model, OPTIONS, OPTIONS.knots)
    assert loaded is not built
    for a, b in zip(evaluate(built), evaluate(loaded), strict=True):
        assert np.array_equal(a, b)
    # Another grid in the same process takes them from the first grid's transcription.
    fine = transcriptions.transcription_for(model, OPTIONS, (6, 3))
    assert fine.functions[0] is loaded.functions[0]
    assert fine.layout.size > loaded.layout.size


def test_a_changed_model_or_option_or_a_corrupt_file_builds_anew(fresh: Path) -> None:
    model = load_model("five-link")
    key = transcriptions.NlpStructure.of(model, OPTIONS, OPTIONS.knots, None)
    path = transcriptions.functions_file(key)
    data = yaml.safe_load(builtin_text("five-link"))
    data["links"][2]["mass"] = 4.5
    heavier = model_from_dict(data)
    other_model = transcriptions.functions_file(
        transcriptions.NlpStructure.of(heavier, OPTIONS, OPTIONS.knots, None))
    no_ankle = OPTIONS.replace(ankle=False)
    other_option = transcriptions.functions_file(
        transcriptions.NlpStructure.of(model, no_ankle, OPTIONS.knots, None))
    other_grid = transcriptions.functions_file(
        transcriptions.NlpStructure.of(model, OPTIONS, (6, 3), None))
    assert len({path, other_model, other_option}) == 3
    assert other_grid == path           # the functions do not depend on the grid
    path.write_bytes(b"not a pickle")
    assert transcriptions.cached_functions(path) is None
    tr = transcriptions.transcription_for(model, OPTIONS, OPTIONS.knots)
    assert transcriptions.cached_functions(path) is not None       # replaced
    assert np.all(np.isfinite(evaluate(tr)[0]))


def test_compiled_walking_nlp_is_the_point_derivatives_or_refused() -> None:
    from gaitopt.gait.options.gait_options import GaitOptionsError

    separated = OPTIONS.replace(transcription="hermite-simpson-separated")
    assert transcriptions.evaluation_mode(separated, None) == "points"
    assert transcriptions.evaluation_mode(separated, "codegen") == "points"
    assert transcriptions.evaluation_mode(OPTIONS, None) is None
    with pytest.raises(GaitOptionsError, match="compiled: the 'hermite-simpson' NLP"):
        gait_solve.solve_walking(load_model("five-link"), OPTIONS, compiled="codegen")
