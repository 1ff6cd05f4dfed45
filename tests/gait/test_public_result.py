"""One public result: a solve hands users a :class:`Gait` and nothing else
(docs/architecture.md, "One public result").

The staged run and its stage records (:mod:`gaitopt.gait.solve.staged_run`), the diagnosis
object and the collocation engine's :class:`gaitopt.ocp.Result` are internal: neither
``gaitopt.__all__`` nor the API reference (docs/api.md) names them, and what a user wants of
a solve, the diagnosis of a failed one included, is reachable from its gait.
"""

from __future__ import annotations

import importlib
import re
import typing
from pathlib import Path

import pytest

import gaitopt
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.gait.solve.diagnose import Diagnosis
from gaitopt.gait.solve.staged_run import StagedRun, StageRecord
from gaitopt.ocp import Result
from tests.gait.conftest import Solved

DOCS = Path(__file__).resolve().parents[2] / "docs"

#: The internal result types and the internal solve: never public.
INTERNAL: tuple[object, ...] = (StagedRun, StageRecord, Diagnosis, Result)
INTERNAL_NAMES = ("StagedRun", "StageRecord", "Diagnosis", "solve_staged_run",
                  "gait_from_run", "WalkingSolution", "StageReport", "solve_gait_solution")
#: Modules whose classes are internal results (exceptions raised to users excepted).
INTERNAL_MODULES = ("gaitopt.gait.solve.", "gaitopt.ocp")

#: A solve forced to fail fast: 3 IPOPT iterations per stage, no speed continuation.
FAILING = GaitOptions.paper(max_iter=3, continuation=False)


def _is_internal_result(obj: object) -> bool:
    if any(obj is internal for internal in INTERNAL):
        return True
    return (isinstance(obj, type) and not issubclass(obj, BaseException)
            and obj.__module__.startswith(INTERNAL_MODULES))


def test_the_front_door_exports_gait_as_the_only_result_of_a_solve() -> None:
    assert "Gait" in gaitopt.__all__
    assert not set(INTERNAL_NAMES) & set(gaitopt.__all__)
    exported = {name: getattr(gaitopt, name) for name in gaitopt.__all__}
    assert [n for n, obj in exported.items() if _is_internal_result(obj)] == []
    assert typing.get_type_hints(gaitopt.solve_gait)["return"] is Gait


def _documented(text: str) -> list[str]:
    """The dotted names of the API page's autodoc directives."""
    return re.findall(r"^\.\. auto\w+:: (\S+)$", text, flags=re.MULTILINE)


def _resolve(dotted: str) -> object:
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(module), name)


def test_the_api_reference_names_no_internal_result() -> None:
    text = (DOCS / "api.md").read_text(encoding="utf-8")
    names = _documented(text)
    assert "gaitopt.Gait" in names
    for word in INTERNAL_NAMES:
        assert not re.search(rf"\b{word}\b", text), word
    internal = [n for n in names if "." in n and _is_internal_result(_resolve(n))]
    assert internal == []
    assert [n for n in names if n.startswith("gaitopt.ocp")] == []


def test_a_failed_solve_s_diagnosis_is_reachable_from_its_gait(tmp_path: Path) -> None:
    lines: list[str] = []
    gait = gaitopt.solve_gait("five-link", FAILING, progress=lines.append)
    assert isinstance(gait, Gait) and not gait.success
    assert gait.status == "Maximum_Iterations_Exceeded"
    # The progress lines are text, one per stage, and the gait keeps every stage.
    assert lines and all(isinstance(line, str) for line in lines)
    assert len(lines) == len(gait.stages) == len(gait.solver["stages"])
    assert lines[0].startswith("relaxed contact") and "FAILED" in lines[0]
    first = gait.stages[0]
    assert first["name"] == "relaxed contact" and not first["success"]
    assert first["violation"] > 0 and "speed" in first["parameters"]
    # The diagnosis: the failed stage, why, and what to change.
    diagnosis = gait.diagnosis
    assert diagnosis is not None
    assert diagnosis.startswith("the solve failed at stage '")
    assert "(Maximum_Iterations_Exceeded)" in diagnosis
    assert "What you can change:" in diagnosis
    # Kept with the failed gait's file.
    path = gait.save(tmp_path / "failed.gait.json", allow_failed=True)
    assert Gait.load(path).diagnosis == diagnosis


def test_a_converged_gait_has_no_diagnosis_and_keeps_its_stages(
        default_solved: Solved) -> None:
    gait = default_solved.gait
    assert gait.success and gait.diagnosis is None and "diagnosis" not in gait.solver
    assert [s["name"] for s in gait.stages] == [s.name for s in default_solved.solution.stages]
    last = gait.stages[-1]
    assert last["success"] and last["violation"] < 1e-6
    assert last["parameters"]["speed"] == pytest.approx(gait.speed)


def test_a_diagnosis_that_is_not_text_is_refused(default_solved: Solved) -> None:
    data = default_solved.gait.to_dict()
    data["solver"]["diagnosis"] = 3
    with pytest.raises(GaitFileError, match="solver.diagnosis"):
        Gait.from_dict(data)
