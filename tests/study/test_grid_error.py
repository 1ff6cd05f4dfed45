"""The grid error of a study (:mod:`gaitopt.study.grid_error`): pairing the study's points
with the check sweep's, the estimates and the sentences the report prints, and the report's
statements next to each figure (synthetic sweeps, no solve)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.study.grid_error import (
    CHECK_DIR,
    REFINE_DIR,
    GridError,
    check_knots,
    grid_error,
    sweep_grid,
)
from gaitopt.study.plan import SETTINGS_FILE, with_option_defaults
from gaitopt.study.summary import SummaryRow, variant_flags, write_summary
from gaitopt.viz.report import write_report
from tests.viz.synthetic import synthetic_sweep


def row(variant: str, speed_m_min: float, cost: float, step: float, *,
        free: bool = False, success: bool = True) -> SummaryRow:
    ankle, impulse = variant_flags(variant)
    return SummaryRow(variant=variant, ankle=ankle, impulse=impulse,
                      speed_mode="free" if free else "fixed", speed_m_s=speed_m_min / 60.0,
                      speed_m_min=speed_m_min, step_length=step, step_time=step * 60.0
                      / speed_m_min, cost=cost if success else math.nan, status="ok",
                      success=success, iterations=10, wall_time_s=1.0, file="")


STUDY = [row("ankle", 12.0, 431.56, 0.1081), row("ankle", 30.0, 642.61, 0.2082),
         row("ankle", 60.0, 1769.8, 0.3574), row("ankle", 13.33, 428.67, 0.1172, free=True),
         row("plain", 12.0, 539.68, 0.1090)]
CHECK = [row("ankle", 12.0, 431.17, 0.1090), row("ankle", 30.0, 640.0, 0.2100),
         row("ankle", 60.0, 1750.0, 0.3600, success=False),
         row("ankle", 13.21, 428.70, 0.1178, free=True)]


def test_points_pair_by_variant_mode_and_speed() -> None:
    errors = GridError.compare(STUDY, CHECK, knots=(16, 6), control_model="jumps",
                               check=(24, 8))
    pairs = {(p.row.variant, p.row.speed_mode, p.row.speed_m_min) for p in errors.points}
    # 60 m/min failed on the check grid; plain was not checked.
    assert pairs == {("ankle", "fixed", 12.0), ("ankle", "fixed", 30.0),
                     ("ankle", "free", 13.33)}
    free = errors.free("ankle")
    assert free is not None
    assert free.speed_m_min == pytest.approx(13.21 - 13.33)
    assert free.step_length == pytest.approx(0.1178 - 0.1172)
    assert free.cost == pytest.approx(abs(428.67 - 428.70) / 428.70)
    # The estimate is the change times the first-order factor 24 / (24 - 16) = 3.
    assert {p.factor for p in errors.points} == {3.0}
    worst = 3 * abs(642.61 - 640.0) / 640.0
    below = 3 * abs(431.56 - 431.17) / 431.17
    assert errors.statement() == (
        "Grid: 16+6 knots, control model jumps. Error estimate (3 x the change to 24+8 knots "
        f"at 2 fixed-speed points, 1 speed-free optimum): cost within {100 * worst:.2f} %; "
        f"above 1 % at 1 of 3 points (30 m/min), within {100 * below:.2f} % at the others.")
    assert "step length within 0.0054 m" in errors.statement(what="step length")
    only12 = errors.statement(errors.of([STUDY[0]]))
    assert f"at 1 fixed-speed point): cost within {100 * below:.2f} %" in only12


def test_without_a_check_sweep_the_statement_gives_the_grid_only() -> None:
    errors = GridError((8, 5), "paper", None, ())
    assert errors.statement() == ("Grid: 8+5 knots, control model paper; no error estimate "
                                  "(no point solved on a finer grid).")


def test_check_grids() -> None:
    assert check_knots(GaitOptions().knots) == (24, 8)
    assert check_knots(GaitOptions.paper().knots) == (16, 6)
    assert check_knots((40, 10)) == (60, 15)


def settings(folder: Path, knots: tuple[int, int], control_model: str | None) -> None:
    options: dict[str, object] = {"knots": list(knots)}
    if control_model is not None:
        options["control_model"] = control_model
    folder.mkdir(parents=True, exist_ok=True)
    (folder / SETTINGS_FILE).write_text(json.dumps({"settings": {"options": options}}))


def test_the_grid_of_a_sweep_written_before_control_models_is_the_papers(
        tmp_path: Path) -> None:
    settings(tmp_path, (8, 5), None)
    assert sweep_grid(tmp_path) == ((8, 5), "paper")
    assert sweep_grid(tmp_path / "missing") is None
    old = with_option_defaults({"options": {"knots": [8, 5]}})
    assert old["options"]["control_model"] == "paper"
    saved = GaitOptions.paper().to_dict()
    del saved["control_model"]
    assert GaitOptions.from_dict(saved) == GaitOptions.paper()


def test_the_report_states_each_figures_grid_and_error(tmp_path: Path) -> None:
    """A synthetic sweep on 16+6 and its check sweep with every cost 1 % higher at 12 and
    24 m/min and the free optimum 0.5 m/min faster: the captions and the headline say so."""
    rows = synthetic_sweep(tmp_path / "sweep", speeds_m_min=(6, 12, 24, 50), n_samples=21)
    settings(tmp_path / "sweep", (16, 6), "jumps")
    check = tmp_path / "sweep" / CHECK_DIR
    settings(check, (24, 8), "jumps")
    moved = [row(r.variant, r.speed_m_min + (0.5 if r.speed_mode == "free" else 0.0),
                 r.cost * 1.01, r.step_length + 0.001, free=r.speed_mode == "free")
             for r in rows if r.speed_mode == "free" or r.speed_m_min in (12.0, 24.0)]
    write_summary(check / "summary.csv", moved)
    errors = grid_error(tmp_path / "sweep", rows)
    assert errors is not None and len(errors.points) == len(moved)
    html = (write_report(tmp_path / "sweep", tmp_path / "out", svg=False).html
            .read_text(encoding="utf-8"))
    expected = f"cost within {300 * 0.01 / 1.01:.2f} %"
    assert html.count("Grid: 16+6 knots, control model jumps. Error estimate (3 x the change "
                      "to 24+8 knots") >= 8  # headline, Figs. 3-8, stick figures
    assert f"at 8 fixed-speed points, 4 speed-free optima): {expected}" in html  # Fig. 3
    assert "step length within 0.0030 m" in html  # Fig. 4
    assert "speed +0.50 m/min, step +0.0010 m; error estimate (3 x): cost " \
           f"{300 * 0.01 / 1.01:.2f} %, speed 1.50 m/min, step 0.0030 m" in html  # headline
    # Fig. 7 shows the optima without impulse (checked) and gaits at 50 m/min (not checked).
    assert f"at 2 speed-free optima): {expected}" in html


def test_the_statement_says_where_the_estimate_exceeds_one_percent() -> None:
    study = [row("plain", v, 1000.0, 0.3) for v in (12.0, 45.0, 60.0)]
    check = [row("plain", 12.0, 999.0, 0.3), row("plain", 45.0, 1015.0, 0.3),
             row("plain", 60.0, 1020.0, 0.3)]
    errors = GridError.compare(study, check, knots=(16, 6), control_model="jumps",
                               check=(24, 8))
    text = errors.statement()
    assert f"cost within {300 * 20 / 1020:.2f} %" in text
    assert f"above 1 % at 2 of 3 points (45-60 m/min), within {300 / 999:.2f} % at the " \
           "others" in text


def test_a_refined_point_reports_its_refined_value_and_its_last_two_grids() -> None:
    """45 m/min changed by 1.5 % to the check grid and was re-solved: the study reports the
    refinement grid's value, with twice the change from the check grid as its estimate (the
    first-order error of 36 knots from 24 and 36)."""
    study = [row("plain", v, 1000.0, 0.3) for v in (12.0, 45.0)]
    check = [row("plain", 12.0, 999.0, 0.3), row("plain", 45.0, 1015.0, 0.3)]
    unrefined = GridError.compare(study, check, knots=(16, 6), control_model="jumps",
                                  check=(24, 8))
    assert [p.row.speed_m_min for p in unrefined.to_refine()] == [45.0]
    fine = [SummaryRow(**{**vars(row("plain", 45.0, 1020.0, 0.298)),
                          "file": "gaits/plain/speed-045.00m_min.gait.json"})]
    errors = GridError.compare(study, check, knots=(16, 6), control_model="jumps",
                               check=(24, 8), refine_rows=fine, refine=(36, 12))
    assert errors.refine_knots == (36, 12) and errors.to_refine() == []
    p45 = errors.of([study[1]])[0]
    assert p45.refined and p45.row.cost == 1020.0 and p45.factor == 2.0
    assert p45.cost == pytest.approx(5.0 / 1020.0)  # |J(36+12) - J(24+8)| / J(36+12)
    assert p45.cost_error == pytest.approx(10.0 / 1020.0)
    assert p45.step_length == pytest.approx(0.298 - 0.3)  # finer minus coarser
    assert p45.row.file == "refine-grid/gaits/plain/speed-045.00m_min.gait.json"
    reported = errors.reported(study)
    assert [r.cost for r in reported] == [1000.0, 1020.0]
    text = errors.statement()
    assert text == (
        "Grid: 16+6 knots, control model jumps, and 36+12 knots at the 1 point (45 m/min) "
        "whose estimate exceeded 1 % (re-solved). Error estimate (first order from each "
        "point's last two grids: 3 x the change to 24+8 knots, 2 x the change from 24+8 knots "
        f"to 36+12 knots at the re-solved points; at 2 fixed-speed points): cost within "
        f"{1000 / 1020:.2f} %.")
    # A figure without the refined point says nothing of the refinement.
    assert "36+12" not in errors.statement(errors.of([study[0]]))


def test_a_free_optimum_whose_speed_moves_over_one_percent_is_refined() -> None:
    study = [row("ankle", 13.0, 430.0, 0.117, free=True)]
    check = [row("ankle", 13.3, 430.1, 0.117, free=True)]
    errors = GridError.compare(study, check, knots=(16, 6), control_model="jumps",
                               check=(24, 8))
    p = errors.to_refine()
    assert len(p) == 1 and p[0].relative == pytest.approx(3 * 0.3 / 13.3)


def test_grid_error_reads_the_refinement_sweep(tmp_path: Path) -> None:
    study = [row("plain", 45.0, 1000.0, 0.3)]
    settings(tmp_path, (16, 6), "jumps")
    settings(tmp_path / CHECK_DIR, (24, 8), "jumps")
    write_summary(tmp_path / CHECK_DIR / "summary.csv", [row("plain", 45.0, 1015.0, 0.3)])
    settings(tmp_path / REFINE_DIR, (36, 12), "paper")  # another control model: ignored
    write_summary(tmp_path / REFINE_DIR / "summary.csv", [row("plain", 45.0, 1020.0, 0.3)])
    errors = grid_error(tmp_path, study)
    assert errors is not None and errors.refine_knots is None
    settings(tmp_path / REFINE_DIR, (36, 12), "jumps")
    errors = grid_error(tmp_path, study)
    assert errors is not None and errors.refine_knots == (36, 12)
    assert errors.reported(study)[0].cost == 1020.0


def test_a_point_refined_twice_reports_its_finest_grid_and_the_one_before() -> None:
    """45 m/min: re-solved on 36 + 12 (step still 1.3 % off by 2 x its change) and again on
    54 + 18: the study reports the 54 + 18 row with 2 x its change from 36 + 12 (54 / 27),
    says which grid each re-solved point is on, and states step lengths relative too."""
    from gaitopt.study.grid_error import RefineLevel

    study = [row("plain", v, 1000.0, 0.3) for v in (12.0, 45.0)]
    check = [row("plain", 12.0, 999.0, 0.3), row("plain", 45.0, 1015.0, 0.3)]
    level1 = RefineLevel((row("plain", 45.0, 1016.0, 0.298),), (36, 12), "refine-grid")
    once = GridError.compare(study, check, knots=(16, 6), control_model="jumps",
                             check=(24, 8), refine_levels=[level1])
    p45 = once.of([study[1]])[0]
    assert p45.level == 1 and p45.step_relative == pytest.approx(2 * 0.002 / 0.298)
    assert [p.row.speed_m_min for p in once.to_refine(2)] == [45.0]  # 1.3 % > 1 %
    assert once.to_refine(1) == [] == once.to_refine()  # 12 m/min is within 1 %
    level2 = RefineLevel((row("plain", 45.0, 1016.5, 0.2976),), (54, 18), "refine-grid-2")
    twice = GridError.compare(study, check, knots=(16, 6), control_model="jumps",
                              check=(24, 8), refine_levels=[level1, level2])
    p45 = twice.of([study[1]])[0]
    assert (p45.level, p45.grid, p45.check_grid, p45.factor) == (2, (54, 18), (36, 12), 2.0)
    assert p45.row.cost == 1016.5 and p45.check.cost == 1016.0
    assert p45.step_error == pytest.approx(2 * 0.0004)
    assert twice.levels == ((36, 12), (54, 18)) and twice.to_refine(3) == []
    assert twice.reported(study)[1].cost == 1016.5
    text = twice.statement(what="step length")
    assert "54+18 knots at the 1 point (45 m/min)" in text
    assert "2 x the change from 36+12 knots to 54+18 knots" in text
    assert f"step length within 0.0008 m and {100 * 0.0008 / 0.2976:.2f} %" in text


def test_grid_error_reads_every_refinement_level(tmp_path: Path) -> None:
    study = [row("plain", 45.0, 1000.0, 0.3)]
    settings(tmp_path, (16, 6), "jumps")
    settings(tmp_path / CHECK_DIR, (24, 8), "jumps")
    write_summary(tmp_path / CHECK_DIR / "summary.csv", [row("plain", 45.0, 1015.0, 0.3)])
    for folder, knots, cost in ((REFINE_DIR, (36, 12), 1020.0),
                                (f"{REFINE_DIR}-2", (54, 18), 1021.0)):
        settings(tmp_path / folder, knots, "jumps")
        write_summary(tmp_path / folder / "summary.csv", [row("plain", 45.0, cost, 0.3)])
    errors = grid_error(tmp_path, study)
    assert errors is not None and errors.levels == ((36, 12), (54, 18))
    assert errors.reported(study)[0].cost == 1021.0
    assert errors.points[0].cost_error == pytest.approx(2.0 / 1021.0)
