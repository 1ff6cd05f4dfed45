"""The cost study's accuracy pass by default: on for models with feet (the heel-toe walk), off
for the paper's walk; a case whose pass failed or did not run is marked as not within the
accuracy in the table, never passed silently. No solve: fake summaries and notes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from gaitopt.gait.api import solve_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.robot import RobotModel
from gaitopt.study.cost_accuracy import (
    ACCURACY_ROUNDS,
    ACCURATE_FILE,
    ACCURATE_NOTE,
    AccuracyOutcome,
    AccuracyTask,
    accuracy_failure,
    accurate_gait,
    save_accurate,
)
from gaitopt.study.cost_study import ACCURACY, CostStudyError, CostStudySpec, collect_rows
from gaitopt.study.summary import SUMMARY_FILE, SummaryRow, write_summary


def test_the_pass_runs_by_default_for_feet_only(five_link: RobotModel,
                                                 seven_link: RobotModel) -> None:
    auto = CostStudySpec(models=(five_link, seven_link))
    assert auto.accuracy_of(five_link) is None
    assert auto.accuracy_of(seven_link) == ACCURACY
    assert auto.accuracy_of("seven-link") == ACCURACY  # by name, as the sweeps name it
    assert auto.refines and not CostStudySpec(models=(five_link,)).refines
    on = CostStudySpec(models=(five_link, seven_link), accuracy_pass="on")
    assert on.accuracy_of(five_link) == on.accuracy_of(seven_link) == ACCURACY
    off = CostStudySpec(models=(five_link, seven_link), accuracy_pass="off")
    assert off.accuracy_of(five_link) is None and off.accuracy_of(seven_link) is None
    assert not off.refines
    assert CostStudySpec(models=(seven_link,), accuracy=None).accuracy_of(seven_link) is None
    with pytest.raises(CostStudyError, match="accuracy_pass: 'sometimes'; allowed: auto, on"):
        CostStudySpec(models=(five_link,), accuracy_pass="sometimes")
    models = {m["name"]: m for m in auto.settings()["models"]}
    assert models["five-link"]["accuracy"] is None
    assert models["seven-link"]["accuracy"] == ACCURACY


def _case(folder: Path, cost: float) -> str:
    """A converged speed-free optimum in ``folder``'s summary; its gait file's path."""
    folder.mkdir(parents=True, exist_ok=True)
    row = SummaryRow(variant="ankle+impulse", ankle=True, impulse=True, speed_mode="free",
                     speed_m_s=0.9, speed_m_min=54.0, step_length=0.53, step_time=0.59,
                     cost=cost, status="Solve_Succeeded", success=True, iterations=10,
                     wall_time_s=1.0, file="gaits/ankle+impulse/speed-free.gait.json")
    write_summary(folder / SUMMARY_FILE, [row])
    return row.file


def test_a_case_without_its_accurate_gait_is_marked(tmp_path: Path,
                                                     seven_link: RobotModel) -> None:
    spec = CostStudySpec(models=(seven_link,), costs=("metabolic",), resting_powers=(1.2,),
                         start_speed=1.25)
    case = tmp_path / "seven-link" / "metabolic-rest-1.2"
    file = _case(case, 0.22)
    (row,) = collect_rows(spec, tmp_path)
    assert row.success and row.within_accuracy is False
    assert "not within 1 %: no accuracy pass" in row.status

    source = f"seven-link/metabolic-rest-1.2/{file}"
    task = AccuracyTask(key="seven-link/metabolic-rest-1.2", model=seven_link,
                        options=spec.sweeps({})[0].spec.base, text="{}", source=source,
                        cost=0.22)
    failed = AccuracyOutcome(key=task.key, gait=None, status="Maximum_Iterations_Exceeded",
                             wall_time_s=1.0, iterations=3000)
    assert save_accurate(case, task, failed) is None
    assert json.loads((case / ACCURATE_NOTE).read_text())["failed"] is True
    assert accuracy_failure(case, source, 0.22) == "Maximum_Iterations_Exceeded"
    assert accuracy_failure(case, source, 0.23) is None  # another optimum: not its failure
    (row,) = collect_rows(spec, tmp_path)
    assert row.within_accuracy is False and math.isfinite(row.cost_value)
    assert "the accuracy pass failed (Maximum_Iterations_Exceeded)" in row.status

    off = CostStudySpec(models=(seven_link,), costs=("metabolic",), resting_powers=(1.2,),
                        start_speed=1.25, accuracy_pass="off")
    (row,) = collect_rows(off, tmp_path)
    assert row.within_accuracy is None and "within" not in row.status


def test_a_rerun_refines_again_a_gait_short_of_its_rounds(tmp_path: Path,
                                                           five_link: RobotModel) -> None:
    """A case's accurate gait is kept by a rerun when within its accuracy, refined
    ACCURACY_ROUNDS times or stopped by a growing cost estimate; one that an older pass left
    above the accuracy after fewer rounds is solved again (None)."""
    gait = solve_gait(five_link, GaitOptions.paper(speed=0.2, knots=(8, 5), accuracy=None))
    assert gait.success
    source, cost = "five-link/paper/gaits/ankle+impulse/speed-free.gait.json", 431.0
    (tmp_path / ACCURATE_NOTE).write_text(json.dumps({"from": source, "from_cost": cost}))

    def kept(within: bool, rounds: int, diverging: bool | None = None) -> bool:
        data = gait.to_dict()
        data["solver"]["accuracy"] = {**(data["solver"].get("accuracy") or {}),
                                      "within_target": within, "refinements": rounds,
                                      "diverging": diverging}
        Gait.from_dict(data).save(tmp_path / ACCURATE_FILE)
        return accurate_gait(tmp_path, source, cost) is not None

    assert kept(True, 0) and kept(True, ACCURACY_ROUNDS)
    assert not kept(False, ACCURACY_ROUNDS - 1)
    assert not kept(False, ACCURACY_ROUNDS - 1, diverging=False)
    assert kept(False, ACCURACY_ROUNDS)
    # a pass that stopped because its cost estimate grew is final: a rerun would repeat it
    assert kept(False, 2, diverging=True)
    assert accurate_gait(tmp_path, source, cost * 1.01) is None  # another optimum


def test_a_case_whose_speed_the_smoothing_sets_gets_no_pass(
        tmp_path: Path, seven_link: RobotModel, monkeypatch: pytest.MonkeyPatch) -> None:
    """A speed-free optimum whose cost is mostly the smoothing (the work cost, 0 W/kg: 43-51 %
    measured) has no optimal speed of its own: no accuracy pass, not counted within or not
    within, its status says why; below the threshold the pass runs as before."""
    import gaitopt.study.cost_study as cost_study

    spec = CostStudySpec(models=(seven_link,), costs=("work",), start_speed=1.25)
    case = tmp_path / "seven-link" / "work"
    file = _case(case, 0.004)
    (case / file).parent.mkdir(parents=True, exist_ok=True)
    (case / file).write_text("{}", encoding="utf-8")  # the pass reads the winner's file
    shares: list[Path] = []

    def share(path: Path) -> float:
        shares.append(path)
        return 0.45

    monkeypatch.setattr(cost_study, "smoothing_share", share)
    assert cost_study.accuracy_tasks(spec, tmp_path) == []
    (row,) = collect_rows(spec, tmp_path)
    assert row.success and row.within_accuracy is None
    assert cost_study.SMOOTHING_NOTE in row.status and row.smoothing_share == 0.45
    assert shares and all(p == case / file for p in shares)
    monkeypatch.setattr(cost_study, "smoothing_share",
                        lambda path: cost_study.SMOOTHING_SETS_SPEED / 2)
    assert len(cost_study.accuracy_tasks(spec, tmp_path)) == 1
    (row,) = collect_rows(spec, tmp_path)
    assert row.within_accuracy is False and cost_study.SMOOTHING_NOTE not in row.status
