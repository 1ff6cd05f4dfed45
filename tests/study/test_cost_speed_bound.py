"""A cost case whose speed-free optimum ends on a bound of the speed says so: in its status
(``costs.csv``, the report's table) and in the answer, since the optimum of the unbounded
problem lies at or beyond the bound."""

from __future__ import annotations

import math
from pathlib import Path

from gaitopt.robot import load_model
from gaitopt.study.cost_study import CostStudySpec, collect_rows, speed_bound_reached
from gaitopt.study.summary import SUMMARY_FILE, SummaryRow, write_summary
from gaitopt.viz.cost_report import answer_text


def test_speed_bound_reached() -> None:
    bounds = (0.02, 1.5)  # m/s
    assert speed_bound_reached(89.99999969, bounds) == 90.0
    assert speed_bound_reached(1.2, bounds) == 1.2
    assert speed_bound_reached(89.9, bounds) is None
    assert speed_bound_reached(62.5, bounds) is None
    assert speed_bound_reached(math.nan, bounds) is None


def _free_point(directory: Path, speed_m_min: float) -> None:
    row = SummaryRow(variant="ankle+impulse", ankle=True, impulse=True, speed_mode="free",
                     speed_m_s=speed_m_min / 60.0, speed_m_min=speed_m_min, step_length=0.6,
                     step_time=0.6 / (speed_m_min / 60.0), cost=0.47, status="Solve_Succeeded",
                     success=True, iterations=20, wall_time_s=1.0,
                     file="gaits/ankle+impulse/speed-free.gait.json")
    directory.mkdir(parents=True)
    write_summary(directory / SUMMARY_FILE, [row])


def test_a_case_on_the_speed_bound_says_so(tmp_path: Path) -> None:
    spec = CostStudySpec(models=(load_model("five-link"),), costs=("metabolic",),
                         resting_powers=(1.2, 4.8), start_speed=0.2)
    upper = spec.sweeps()[0].spec.base.speed_bounds[1] * 60.0
    _free_point(tmp_path / "five-link" / "metabolic-rest-1.2", 62.5)
    _free_point(tmp_path / "five-link" / "metabolic-rest-4.8", upper * (1 - 1e-9))
    rows = {r.case: r for r in collect_rows(spec, tmp_path)}
    assert rows["metabolic-rest-1.2"].status == "Solve_Succeeded"
    assert rows["metabolic-rest-4.8"].success
    assert rows["metabolic-rest-4.8"].status == (
        f"Solve_Succeeded; at the speed bound {upper:g} m/min")
    # the 4.8 W/kg optimum is nearer people's walk than the 1.2 W/kg one: the answer names it
    answer = " ".join(answer_text(list(rows.values())))
    assert f"{upper:.1f} m/min (at its speed bound)" in answer
    assert "62.5 m/min with" in answer
