"""The linear-algebra options of the fine-grid stages
(``gaitopt.gait.solve.stages.fine_grid_options``):
the two-phase walk solves its target and check grids with IPOPT's fast step computation (in
either formulation) and, in full coordinates, with MUMPS's permuting scaling off; its coarse
stages and every other problem keep IPOPT's and MUMPS's defaults (the measurements behind
the choice: docs/results/benchmarks-gait.md, "MUMPS scaling" and "MUMPS ordering and IPOPT's step
options")."""

from __future__ import annotations

from typing import Any

import pytest

from gaitopt.gait.api import solve_staged_run
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve.stages import (
    FULL_WALK_FINE_GRID_OPTIONS,
    WALK_FINE_GRID_OPTIONS,
    fine_grid_options,
)
from gaitopt.ocp import Transcription
from gaitopt.robot import load_model

KEY = "ipopt.mumps_permuting_scaling"
FAST = "ipopt.fast_step_computation"


def _solved_with(monkeypatch: pytest.MonkeyPatch, options: GaitOptions, key: str = KEY
                 ) -> list[tuple[tuple[int, ...], Any]]:
    """Solve ``options`` and return, per IPOPT call, the knots per phase and the option
    ``key`` it was given (None: the default)."""
    calls: list[tuple[tuple[int, ...], Any]] = []
    original = Transcription.solve

    def recording(self: Transcription, *args: Any, **kwargs: Any) -> Any:
        given = kwargs.get("options") or {}
        calls.append((tuple(m.size for m in self.mesh), given.get(key)))
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Transcription, "solve", recording)
    assert solve_staged_run(load_model("five-link"), options).success
    return calls


def test_the_full_walk_solves_only_its_fine_grids_without_permuting_scaling(
        monkeypatch: pytest.MonkeyPatch) -> None:
    calls = _solved_with(monkeypatch, GaitOptions(formulation="full", knots=(16, 6)))
    coarse = [value for knots, value in calls if knots == (8, 5)]
    fine = [value for knots, value in calls if knots != (8, 5)]
    assert coarse and all(value is None for value in coarse)
    # the target grid, its release and the check grid (16 + 6, 24 + 8)
    assert len(fine) >= 3 and all(value == 0 for value in fine)


def test_other_problems_keep_mumps_defaults(monkeypatch: pytest.MonkeyPatch) -> None:
    calls = _solved_with(monkeypatch, GaitOptions(knots=(16, 6)))
    assert any(knots != (8, 5) for knots, _ in calls)
    assert all(value is None for _, value in calls)
    assert fine_grid_options(GaitOptions(formulation="full", gait="heel-toe")) == {}
    assert fine_grid_options(GaitOptions(formulation="full")) == {
        **WALK_FINE_GRID_OPTIONS, **FULL_WALK_FINE_GRID_OPTIONS}


@pytest.mark.parametrize("formulation", ["reduced", "full"])
def test_the_walk_computes_only_its_fine_steps_fast(monkeypatch: pytest.MonkeyPatch,
                                                    formulation: str) -> None:
    calls = _solved_with(monkeypatch, GaitOptions(formulation=formulation, knots=(16, 6)),
                         FAST)
    coarse = [value for knots, value in calls if knots == (8, 5)]
    fine = [value for knots, value in calls if knots != (8, 5)]
    assert coarse and all(value is None for value in coarse)
    assert len(fine) >= 3 and all(value == "yes" for value in fine)
