"""The cost study's continuation between cases (gaitopt.study.cost_continuation): the order the
cases are solved in, which case starts which, the lowest of a case's starts, and the table's
accuracy columns. No solve: fake summaries."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from gaitopt.robot import RobotModel
from gaitopt.study.cost_continuation import (
    NEIGHBOUR_DIR,
    case_neighbour,
    free_candidates,
    resolve_neighbour,
)
from gaitopt.study.cost_study import CostCase, CostStudyError, CostStudySpec
from gaitopt.study.cost_table import (
    COST_COLUMNS,
    CostRow,
    cost_table_csv,
    read_cost_table,
)
from gaitopt.study.summary import SUMMARY_FILE, SummaryRow, write_summary


def M(p: float) -> CostCase:  # noqa: N802  (a case, as the docs write it)
    return CostCase("metabolic", p)


def test_strategy_follows_the_gait(five_link: RobotModel, seven_link: RobotModel) -> None:
    spec = CostStudySpec(models=(five_link, seven_link))
    assert spec.strategy_of(five_link) == "cold"
    assert spec.strategy_of(seven_link) == "continuation"
    assert CostStudySpec(models=(five_link,), strategy="continuation").strategy_of(
        five_link) == "continuation"
    with pytest.raises(CostStudyError, match="strategy: 'warm'"):
        CostStudySpec(models=(five_link,), strategy="warm")
    with pytest.raises(CostStudyError, match="accuracy: 1.5"):
        CostStudySpec(models=(five_link,), accuracy=1.5)


def test_solve_order(five_link: RobotModel, seven_link: RobotModel) -> None:
    """Continuation: metabolic by descending resting power, then work; the paper case is the
    reference with the automatic start and first with a given one. Cold: the study order."""
    spec = CostStudySpec(models=(five_link, seven_link), resting_powers=(2.4, 0.0, 1.2))
    assert [c.tag for c in spec.solve_order(seven_link)] == [
        "metabolic-rest-2.4", "metabolic-rest-1.2", "metabolic-rest-0", "work"]
    assert [c.tag for c in spec.solve_order(five_link)] == [
        "work", "metabolic-rest-0", "metabolic-rest-1.2", "metabolic-rest-2.4"]
    given = CostStudySpec(models=(seven_link,), resting_powers=(2.4, 0.0),
                          start_speed=1.25)
    assert [c.tag for c in given.solve_order(seven_link)] == [
        "paper", "metabolic-rest-2.4", "metabolic-rest-0", "work"]


def test_neighbours() -> None:
    done = [M(0.0), M(0.6), M(1.2)]
    assert case_neighbour(M(2.4), done) == M(1.2)
    assert case_neighbour(M(1.0), [M(1.5), M(0.5)]) == M(0.5)  # a tie: the lower power
    assert case_neighbour(CostCase("work"), done) == M(0.0)
    assert case_neighbour(CostCase("work"), [M(1.2), M(0.6)]) == M(0.6)
    assert case_neighbour(CostCase("paper"), done) is None
    assert case_neighbour(M(0.0), []) is None
    assert case_neighbour(M(0.0), [CostCase("work")]) is None


def test_a_failed_fixed_walk_is_solved_from_the_nearest_converged_case() -> None:
    order = [M(0.0), M(0.6), M(1.2), M(2.4), CostCase("work")]
    assert resolve_neighbour(M(0.0), order, [M(1.2), M(2.4)]) == M(1.2)
    assert resolve_neighbour(CostCase("work"), order, [M(2.4), M(0.6)]) == M(0.6)
    assert resolve_neighbour(M(0.6), order, [CostCase("work")]) == CostCase("work")  # nearest
    assert resolve_neighbour(M(0.6), order, []) is None


def _free_summary(folder: Path, cost: float, *, success: bool = True) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    rows = [SummaryRow(variant="ankle+impulse", ankle=True, impulse=True, speed_mode="free",
                       speed_m_s=1.0, speed_m_min=60.0, step_length=0.55, step_time=0.55,
                       cost=cost if success else math.nan,
                       status="Solve_Succeeded" if success else "failed at speed free: "
                       "Maximum_Iterations_Exceeded", success=success, iterations=10,
                       wall_time_s=1.0,
                       file="gaits/ankle+impulse/speed-free.gait.json" if success else "")]
    write_summary(folder / SUMMARY_FILE, rows)


def test_free_candidates_lowest_first(tmp_path: Path) -> None:
    case = tmp_path / "metabolic-rest-1.2"
    _free_summary(case, 0.21)
    _free_summary(case / NEIGHBOUR_DIR.format(tag="metabolic-rest-0.6"), 0.19)
    _free_summary(case / NEIGHBOUR_DIR.format(tag="metabolic-rest-2.4"), 0.1, success=False)
    found = free_candidates(case, "ankle+impulse")
    assert [(c, where) for c, where, _ in found] == [
        (0.19, "from-metabolic-rest-0.6"), (0.21, "")]
    assert free_candidates(tmp_path / "nothing", "ankle+impulse") == []


def test_table_accuracy_columns_round_trip(tmp_path: Path) -> None:
    rows = [CostRow(model="seven-link", formulation="full", case="metabolic-rest-1.2",
                    cost="metabolic", resting_power=1.2, success=True, status="ok",
                    speed_m_min=61.0, step_length=0.56, step_time=0.55, cost_value=0.197,
                    file="x", start="from metabolic-rest-0.6", other_cost_value=0.2,
                    estimate=0.004, estimate_of="speed", knots="24+16+16+16",
                    within_accuracy=True, smoothing_share=0.011),
            CostRow(model="seven-link", formulation="full", case="work", cost="work",
                    resting_power=math.nan, success=False, status="not solved",
                    speed_m_min=math.nan, step_length=math.nan, step_time=math.nan,
                    cost_value=math.nan, file="")]
    path = tmp_path / "costs.csv"
    path.write_text(cost_table_csv(rows), encoding="utf-8")
    back = read_cost_table(path)
    assert [r.as_csv_dict() for r in back] == [r.as_csv_dict() for r in rows]
    assert back[0].within_accuracy is True and back[1].within_accuracy is None
    assert back[0].smoothing_share == 0.011 and math.isnan(back[1].smoothing_share)
    # a table written before the accuracy columns reads with them empty
    old = [c for c in COST_COLUMNS if c not in ("estimate", "estimate_of", "knots",
                                                 "within_accuracy", "smoothing_share")]
    lines = cost_table_csv(rows[:1]).splitlines()
    header = lines[0].split(",")
    cells = lines[1].split(",")
    path.write_text(",".join(old) + "\n" + ",".join(
        cells[header.index(c)] for c in old) + "\n", encoding="utf-8")
    (row,) = read_cost_table(path)
    assert row.knots == "" and row.within_accuracy is None and math.isnan(row.estimate)
