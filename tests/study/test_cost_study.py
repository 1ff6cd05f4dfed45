"""The cost study (``gaitopt.study.cost_study``, ``cost_findings``, ``viz.cost_report`` and
``gaitopt study --costs``).

The fast tests feed hand-made sweep summaries (the rows a sweep would write) through the
collection, the findings and the report; one slow test runs the command end to end.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.record.file import Gait
from gaitopt.robot import RobotModel, load_model
from gaitopt.robot.loader import model_from_dict
from gaitopt.study.cost_accuracy import ACCURATE_FILE, ACCURATE_NOTE
from gaitopt.study.cost_findings import COST_FINDING_IDS, assess_cost_findings, ranked
from gaitopt.study.cost_start import given_start
from gaitopt.study.cost_study import (
    COST_STUDY_FILE,
    DIRECT_FILE,
    CostCase,
    CostStudyError,
    CostStudySpec,
    collect_rows,
    write_settings,
)
from gaitopt.study.cost_table import (
    COST_TABLE_FILE,
    CostRow,
    human_distance,
    read_cost_table,
    write_cost_table,
)
from gaitopt.study.plan import START_SPEED
from gaitopt.study.summary import SUMMARY_FILE, SummaryRow, write_summary
from gaitopt.viz.cost_report import answer_text, write_cost_report

COMPASS = Path(__file__).parents[1] / "analysis" / "data" / "compass.yaml"


def _row(case: str, cost: str, speed: float, step: float, *, rest: float = math.nan,
         model: str = "five-link", success: bool = True) -> CostRow:
    return CostRow(model=model, formulation="reduced", case=case, cost=cost,
                   resting_power=rest, success=success,
                   status="Solve_Succeeded" if success else "failed at solve",
                   speed_m_min=speed if success else math.nan,
                   step_length=step if success else math.nan,
                   step_time=step / (speed / 60.0) if success else math.nan,
                   cost_value=1.0 if success else math.nan, file="")


def _metabolic(rest: float, speed: float, step: float, *, model: str = "five-link",
               success: bool = True) -> CostRow:
    return _row(f"metabolic-rest-{rest:g}", "metabolic", speed, step, rest=rest, model=model,
                success=success)


# -- the plan ---------------------------------------------------------------------------------

def test_cases_and_their_sweeps(five_link: RobotModel) -> None:
    spec = CostStudySpec(models=(five_link,), resting_powers=(2.4, 0.0, 1.2),
                         regularization=0.01)
    assert [c.tag for c in spec.cases] == ["paper", "work", "metabolic-rest-0",
                                          "metabolic-rest-1.2", "metabolic-rest-2.4"]
    sweeps = spec.sweeps({"five-link": given_start(START_SPEED)})
    assert [s.subdir for s in sweeps] == [f"five-link/{c.tag}" for c in spec.cases]
    for s in sweeps:
        base = s.spec.base
        assert s.formulation == "reduced" and base.formulation == "reduced"
        assert base.cost == s.case.cost
        # the regularisation goes to the costs of transport only
        assert base.cost_regularization == (0.0 if s.case.cost == "paper" else 0.01)
        assert s.spec.speeds == (START_SPEED,) and s.spec.free_speed
        assert s.spec.variants == ("ankle+impulse",)
    assert [s.spec.base.resting_power for s in sweeps[2:]] == [0.0, 1.2, 2.4]
    assert all(s.spec.base.swing_clearance is None for s in sweeps)
    clear = CostStudySpec(models=(five_link,), costs=("work",), swing_clearance=0.02,
                          start_speed=START_SPEED)
    assert [s.spec.base.swing_clearance for s in clear.sweeps()] == [0.02]
    assert clear.sweeps()[0].direct_task().options.swing_clearance == 0.02
    assert clear.sweeps()[0].direct_task().options.speed is None
    # A model that walks fast starts its cases near its own optimum.
    fast = CostStudySpec(models=(five_link,), costs=("metabolic",), resting_powers=(1.2,),
                         start_speed=1.25)
    assert fast.sweeps()[0].spec.speeds == (1.25,)
    assert fast.settings()["start_speed_m_min"] == pytest.approx(75.0)
    assert fast.settings()["models"][0]["start"]["rule"] == "given"
    even = CostStudySpec(models=(five_link,), costs=("paper",), knot_spacing="uniform")
    assert even.sweeps()[0].spec.base.knot_spacing == "uniform"
    assert even.sweeps()[0].direct_task().options.knot_spacing == "uniform"


def test_formulation_auto_is_reduced_only_for_the_five_link_shape(five_link: RobotModel) -> None:
    compass = load_model(COMPASS)
    spec = CostStudySpec(models=(five_link, compass), costs=("paper",))
    assert spec.formulation_of(five_link) == "reduced"
    assert spec.formulation_of(compass) == "full"
    assert CostStudySpec(models=(five_link,), formulation="full").formulation_of(
        five_link) == "full"


def test_gait_auto_is_heel_toe_for_a_model_with_feet(five_link: RobotModel) -> None:
    """Two contact points on the first contact's link (a foot: heel and toe) make the gait
    the heel-toe walk; the five-link model walks the paper's walk."""
    data = five_link.to_dict()
    data["name"] = "heeled"
    data["contacts"] = [{"name": "heel_1", "link": "shank_1", "at": [0.5, -0.02]},
                        {"name": "toe_1", "link": "shank_1", "at": [0.5, 0.08]},
                        {"name": "heel_2", "link": "shank_2", "at": [0.5, -0.02]},
                        {"name": "toe_2", "link": "shank_2", "at": [0.5, 0.08]}]
    data["actuators"] = [a for a in data["actuators"] if a.get("contact") is None]
    heeled = model_from_dict(data)
    spec = CostStudySpec(models=(five_link, heeled), costs=("paper",))
    assert (spec.gait_of(five_link), spec.gait_of(heeled)) == ("walk", "heel-toe")
    five, feet = spec.sweeps()
    assert (five.spec.base.gait, feet.spec.base.gait) == ("walk", "heel-toe")
    assert feet.formulation == "full"
    assert CostStudySpec(models=(heeled,), gait="walk").gait_of(heeled) == "walk"


@pytest.mark.parametrize(("kwargs", "words"), [
    ({"costs": ("paper", "effort")}, "costs"),
    ({"costs": ()}, "costs"),
    ({"resting_powers": (1.2, -0.5)}, "resting powers: -0.5"),
    ({"resting_powers": (1.2, 1.2)}, "at most once"),
    ({"resting_powers": ()}, "resting powers"),
    ({"regularization": -1.0}, "regularization"),
    ({"swing_clearance": -0.01}, "swing clearance"),
    ({"formulation": "polar"}, "formulation"),
    ({"variant": "both"}, "variant"),
    ({"gait": "hop"}, "gait"),
    ({"start_speed": 0.0}, "start_speed"),
    ({"knot_spacing": "random"}, "knot_spacing"),
    ({"start_speed": float("nan")}, "start_speed"),
])
def test_bad_requests_name_the_setting(five_link: RobotModel, kwargs: dict[str, Any],
                                       words: str) -> None:
    with pytest.raises(CostStudyError, match=words):
        CostStudySpec(models=(five_link,), **kwargs)


def test_two_models_with_one_name_are_refused(five_link: RobotModel) -> None:
    with pytest.raises(CostStudyError, match="share a name"):
        CostStudySpec(models=(five_link, five_link))


# -- the results ----------------------------------------------------------------------------------

def test_human_distance() -> None:
    assert human_distance(80.0, 0.75) == 0.0
    assert human_distance(40.0, 0.75) == pytest.approx(0.5)
    assert human_distance(0.0, 0.0) == pytest.approx(math.sqrt(2.0))
    assert human_distance(80.0, 0.375) == pytest.approx(0.5)


def _summary(path: Path, *, speed_free: float | None, step: float) -> None:
    """The summary a case's sweep writes: the 12 m/min point and the speed-free one."""
    rows = [SummaryRow(variant="ankle+impulse", ankle=True, impulse=True, speed_mode="fixed",
                       speed_m_s=0.2, speed_m_min=12.0, step_length=0.1, step_time=0.5,
                       cost=2.0, status="Solve_Succeeded", success=True, iterations=10,
                       wall_time_s=1.0, file="gaits/ankle+impulse/speed-012.00m_min.gait.json")]
    if speed_free is None:
        rows.append(SummaryRow(variant="ankle+impulse", ankle=True, impulse=True,
                               speed_mode="free", speed_m_s=math.nan, speed_m_min=math.nan,
                               step_length=math.nan, step_time=math.nan, cost=math.nan,
                               status="failed at speed free: Maximum_Iterations_Exceeded",
                               success=False, iterations=3000, wall_time_s=9.0, file=""))
    else:
        rows.append(SummaryRow(variant="ankle+impulse", ankle=True, impulse=True,
                               speed_mode="free", speed_m_s=speed_free / 60.0,
                               speed_m_min=speed_free, step_length=step,
                               step_time=step / (speed_free / 60.0), cost=1.5,
                               status="Solve_Succeeded", success=True, iterations=20,
                               wall_time_s=1.0, file="gaits/ankle+impulse/speed-free.gait.json"))
    write_summary(path / SUMMARY_FILE, rows)


def test_collect_write_read_and_report(five_link: RobotModel, tmp_path: Path) -> None:
    """Rows come from each case's speed-free summary row (a failed or missing case is a failed
    row); ``costs.csv`` reads back as written; the report holds the figure, the ranked table
    and every finding id."""
    spec = CostStudySpec(models=(five_link,), resting_powers=(0.0, 1.2, 4.8))
    write_settings(spec, tmp_path)
    assert (tmp_path / COST_STUDY_FILE).exists()
    made = {"paper": (11.1, 0.107), "work": (2.4, 0.03), "metabolic-rest-0": (3.8, 0.05),
            "metabolic-rest-1.2": (27.2, 0.33)}
    for tag, (v, step) in made.items():
        (tmp_path / "five-link" / tag).mkdir(parents=True)
        _summary(tmp_path / "five-link" / tag, speed_free=v, step=step)
    # metabolic-rest-4.8: the speed-free point failed
    (tmp_path / "five-link" / "metabolic-rest-4.8").mkdir()
    _summary(tmp_path / "five-link" / "metabolic-rest-4.8", speed_free=None, step=0.0)
    rows = collect_rows(spec, tmp_path)
    assert [r.case for r in rows] == [c.tag for c in spec.cases]
    by = {r.case: r for r in rows}
    assert by["metabolic-rest-1.2"].speed_m_min == 27.2
    assert by["metabolic-rest-1.2"].file == ("five-link/metabolic-rest-1.2/gaits/ankle+impulse/"
                                            "speed-free.gait.json")
    assert not by["metabolic-rest-4.8"].success
    assert "Maximum_Iterations" in by["metabolic-rest-4.8"].status
    assert math.isnan(by["metabolic-rest-4.8"].human_distance)
    assert ranked(rows)[0].case == "metabolic-rest-1.2" and ranked(rows)[-1].success is False

    write_cost_table(tmp_path, rows)
    back = read_cost_table(tmp_path / COST_TABLE_FILE)
    assert [r.as_csv_dict() for r in back] == [r.as_csv_dict() for r in rows]

    info = write_cost_report(tmp_path, tmp_path / "report")
    page = info.html.read_text()
    assert "data:image/png;base64," in page
    for fid in COST_FINDING_IDS:
        assert f"finding-five-link-{fid}" in page
    assert page.index(">27.2<") < page.index(">11.1<")  # ranked: nearest to people first
    assert {p.suffix for p in info.figures} == {".png", ".svg"}
    assert info.findings["five-link"]["costs.human_speed"].holds is False


def test_cli_report_of_a_cost_study(five_link: RobotModel, tmp_path: Path) -> None:
    """``gaitopt report DIR`` on a cost-study folder rewrites its report from ``costs.csv``;
    without the table it says to finish the study (exit 2)."""
    spec = CostStudySpec(models=(five_link,), costs=("paper",))
    write_settings(spec, tmp_path)
    result = CliRunner().invoke(cli, ["report", str(tmp_path)])
    assert result.exit_code == 2, result.output
    assert "rerun `gaitopt study --costs" in " ".join(result.output.split())
    assert not (tmp_path / "report" / "report.html").exists()
    write_cost_table(tmp_path, [_row("paper", "paper", 11.1, 0.107)])
    result = CliRunner().invoke(cli, ["report", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "(costs.nearest_human)" in result.output
    assert (tmp_path / "report" / "report.html").exists()


def test_missing_case_is_a_failed_row(five_link: RobotModel, tmp_path: Path) -> None:
    rows = collect_rows(CostStudySpec(models=(five_link,), costs=("paper",)), tmp_path)
    assert len(rows) == 1 and not rows[0].success and rows[0].status == "not solved"


def test_bad_cost_table_names_line_and_column(tmp_path: Path) -> None:
    rows = [_row("paper", "paper", 11.1, 0.107)]
    path = write_cost_table(tmp_path, rows)
    path.write_text(path.read_text().replace("11.1", "fast"))
    with pytest.raises(CostStudyError, match="line 2: column speed_m_min"):
        read_cost_table(path)
    with pytest.raises(CostStudyError, match="cannot read"):
        read_cost_table(tmp_path / "nothing.csv")


# -- the findings ---------------------------------------------------------------------------------

def test_findings_on_a_model_like_the_five_link() -> None:
    """Slow time-free optima, speed growing with the resting power, a human resting power
    far below people's walk: the verdicts and their numbers."""
    rows = [_row("paper", "paper", 11.1, 0.107), _row("work", "work", 2.4, 0.03),
            _metabolic(0.0, 3.8, 0.05), _metabolic(1.2, 27.2, 0.33),
            _metabolic(2.4, 35.1, 0.34), _metabolic(4.8, 43.9, 0.26)]
    f = assess_cost_findings(rows)["five-link"]
    assert [i.id for i in f.items] == list(COST_FINDING_IDS)
    assert f["costs.time_free_slow"].holds is True
    assert f["costs.time_free_slow"].numbers["speed_m_min.work"] == 2.4
    assert f["costs.resting_power_sets_speed"].holds is True
    assert f["costs.human_speed"].holds is False
    assert f["costs.human_speed"].numbers["speed_m_min.metabolic-rest-1.2"] == 27.2
    assert f["costs.human_step_length"].holds is False
    nearest = f["costs.nearest_human"]
    assert nearest.holds is False and "nearest: metabolic-rest-1.2" in nearest.evidence
    # 2.4 W/kg is nearer (0.78 against 0.87) but not physiological: named separately
    assert "of all cases metabolic-rest-2.4" in nearest.evidence


def test_findings_on_a_model_that_walks_like_people() -> None:
    rows = [_row("paper", "paper", 50.0, 0.5, model="m"), _row("work", "work", 10.0, 0.1,
                                                                model="m"),
            _metabolic(0.0, 20.0, 0.3, model="m"), _metabolic(1.2, 75.0, 0.7, model="m"),
            _metabolic(2.4, 70.0, 0.8, model="m")]
    f = assess_cost_findings(rows)["m"]
    assert f["costs.time_free_slow"].holds is False  # the paper cost's 50 m/min
    assert f["costs.resting_power_sets_speed"].holds is False  # 75 then 70
    assert f["costs.human_speed"].holds is True
    assert f["costs.human_step_length"].holds is True
    assert f["costs.nearest_human"].holds is True


def test_findings_cannot_tell_without_the_cases() -> None:
    rows = [_metabolic(1.2, 27.2, 0.33, success=False)]
    f = assess_cost_findings(rows)["five-link"]
    assert all(item.holds is None for item in f.items), [i.evidence for i in f.items]


def test_case_labels() -> None:
    assert CostCase("metabolic", 0.6).tag == "metabolic-rest-0.6"
    assert CostCase("metabolic", 0.6).options() == {"cost": "metabolic", "resting_power": 0.6}
    assert CostCase("work").options() == {"cost": "work"}


# -- the command ----------------------------------------------------------------------------------

@pytest.mark.parametrize(("args", "words"), [
    (["--costs", "--resting-powers", "1.2,-1"], "resting powers: -1"),
    (["--costs", "--resting-powers", "1.2,rest"], "--resting-powers: 'rest'"),
    (["--costs", "--regularization", "-0.1"], "regularization"),
    (["--costs", "--start-speed", "fast"], "--start-speed: speed 'fast'"),
    (["--costs", "--start-speed", "75"], "start_speed = 75"),
    (["--model", "five-link", "--model", "five-link"], "one model"),
    (["--costs", "--model", "five-link", "--model", "five-link"], "share a name"),
])
def test_cli_bad_input_is_a_usage_error(tmp_path: Path, args: list[str], words: str) -> None:
    out = tmp_path / "costs"
    result = CliRunner().invoke(cli, ["study", "-o", str(out), *args])
    assert result.exit_code == 2, result.output
    assert words in " ".join(result.output.split())
    assert "Traceback" not in result.output
    assert not out.exists()


@pytest.mark.slow
def test_cli_cost_study_runs_and_resumes(tmp_path: Path) -> None:
    """``gaitopt study --cost paper``: the paper's cost alone (about 10 s): the table, the
    report and the findings; a rerun keeps both points."""
    out = tmp_path / "costs"
    args = ["study", "--cost", "paper", "--accuracy-pass", "-o", str(out), "--workers", "0"]
    first = CliRunner().invoke(cli, args)
    assert first.exit_code == 0, first.output
    rows = read_cost_table(out / COST_TABLE_FILE)
    assert len(rows) == 1 and rows[0].success and rows[0].case == "paper"
    assert 8.0 < rows[0].speed_m_min < 15.0  # the paper's optimum, about 12 m/min
    assert (out / "report" / "report.html").exists()
    # both starts were solved; the row is the lower optimum, the other's cost beside it
    case = out / "five-link" / "paper"
    costs = {start: Gait.load(case / name).cost_value for start, name in (
        ("from 12 m/min", "gaits/ankle+impulse/speed-free.gait.json"),
        ("direct", DIRECT_FILE))}
    assert rows[0].start == min(costs, key=lambda k: costs[k])
    assert rows[0].other_cost_value == max(costs.values())
    # the row reports the lower optimum refined to 1 % (the accuracy pass), which started
    # from the lower start's file and says its estimate and grid
    note = json.loads((case / ACCURATE_NOTE).read_text(encoding="utf-8"))
    assert note["from_cost"] == min(costs.values())
    accurate = Gait.load(case / ACCURATE_FILE)
    assert rows[0].file == f"five-link/paper/{ACCURATE_FILE}"
    assert rows[0].cost_value == accurate.cost_value
    assert rows[0].within_accuracy is True and rows[0].estimate <= 0.01
    assert rows[0].knots == "+".join(str(k) for k in accurate.solver["accuracy"]["knots"].values())
    again = CliRunner().invoke(cli, args)
    assert again.exit_code == 0, again.output
    text = " ".join(again.output.split())
    assert "2 kept from an earlier run, 0 to solve" in text
    assert "direct solves: 0 solved, 0 failed, 1 kept" in text
    assert "accuracy: 0 solved, 0 failed" in text
    assert read_cost_table(out / COST_TABLE_FILE)[0].as_csv_dict() == rows[0].as_csv_dict()


def test_answer_prefers_peoples_settings() -> None:
    """The answer names the nearest case with people's settings, and the nearest of all when
    that is another (here a resting power four times people's)."""
    rows = [_row("paper", "paper", 11.1, 0.107), _metabolic(1.2, 27.2, 0.33),
            _metabolic(4.8, 43.9, 0.26)]
    (text,) = answer_text(rows)
    assert text.startswith("five-link (reduced): nearest to people's walk the "
                           "metabolic-rest-1.2 cost, 27.2 m/min with 0.330 m steps (34% of")
    assert "; of all cases the metabolic-rest-4.8 cost, 43.9 m/min" in text
