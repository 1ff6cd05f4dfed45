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


@pytest.mark.parametrize(("model_name", "knots"), [("five-link", (5, 4)),
                                                   ("seven-link", (6, 4))])
def test_walking_interval_templates_give_the_derivatives_of_the_mesh(
        model_name: str, knots: tuple[int, int]) -> None:
    # The walking NLP's outer derivatives from interval functions derived once per process
    # (the default of compiled="points") against those derived within this mesh's outer
    # functions: the same sparsity and values at a point near the naive guess (the terms
    # summed in another order: 1e-12 relative). The seven-link heel-toe walk has four
    # phases, knot states and durations that are expressions of the parameters.
    from gaitopt.gait.formulations.select import problem_for
    from gaitopt.gait.options.model_defaults import options_for_model
    from gaitopt.ocp import pointwise, transcribe

    model = load_model(model_name)
    options = options_for_model(model, GaitOptions(knots=knots))
    problem = problem_for(model, options)
    tr = transcribe(problem, method="hermite-simpson-separated", build_solver=False)
    before = pointwise.interval_derivations
    # The point functions compiled (once per model, shared with the other walking tests).
    templates = tr.pointwise_nlp(interval_templates=True)
    whole = tr.pointwise_nlp(interval_templates=False)
    tr.pointwise_nlp(interval_templates=True)  # a second build derives nothing
    assert pointwise.interval_derivations - before <= len(problem.phases)
    rng = np.random.default_rng(7)
    w = tr.initial_guess() / tr.nlp.d_w * (1 + 0.01 * rng.standard_normal(tr.layout.size))
    lam = rng.standard_normal(tr.nlp.lbg.size)
    for kind, fn in whole.functions.items():
        args = [w, []] + ([0.7, lam] if kind == "nlp_hess_l" else [])
        expected, got = fn(*args), templates.functions[kind](*args)
        for e, g in zip(*[r if isinstance(r, list | tuple) else [r] for r in (expected, got)],
                        strict=True):
            assert g.sparsity() == e.sparsity(), kind
            e_nz, g_nz = np.array(e.nonzeros()), np.array(g.nonzeros())
            assert np.all(np.isfinite(e_nz)), kind
            assert np.max(np.abs(g_nz - e_nz), initial=0.0) <= 1e-12 * max(
                1.0, np.max(np.abs(e_nz), initial=0.0)), kind
