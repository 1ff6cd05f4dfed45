"""The cost study's start speed (``gaitopt.study.cost_start``, ``--start-speed auto``) and its
per-model knots.

The rule is checked on hand-made sweep summaries; the command runs with the sweeps, the direct
solves and the report replaced by fakes that write the summaries a sweep would write, so that
what the command asks each sweep to solve (its start speed, its knots) is what is checked.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.robot import RobotModel
from gaitopt.study.cost_start import (
    AUTO_START,
    AUTO_START_STEP_M_MIN,
    auto_start_speed,
    given_start,
)
from gaitopt.study.cost_study import (
    COST_STUDY_FILE,
    DEFAULT_KNOTS,
    STUDY_MAX_ITER,
    CostCase,
    CostStudyError,
    CostStudySpec,
    collect_rows,
    start_choice,
    start_choices,
)
from gaitopt.study.cost_table import COST_TABLE_FILE, read_cost_table
from gaitopt.study.plan import START_SPEED, SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, SummaryRow, write_summary

VARIANT = "ankle+impulse"


def _rows(start_m_min: float, free_m_min: float | None, step: float = 0.3) -> list[SummaryRow]:
    """A case's sweep summary: the cold point at ``start_m_min`` and the speed-free optimum
    (failed when ``free_m_min`` is None)."""
    cold = SummaryRow(variant=VARIANT, ankle=True, impulse=True, speed_mode="fixed",
                      speed_m_s=start_m_min / 60.0, speed_m_min=start_m_min, step_length=step,
                      step_time=step / (start_m_min / 60.0), cost=2.0,
                      status="Solve_Succeeded", success=True, iterations=10, wall_time_s=1.0,
                      file=f"gaits/{VARIANT}/speed-{start_m_min:06.2f}m_min.gait.json")
    if free_m_min is None:
        free = SummaryRow(variant=VARIANT, ankle=True, impulse=True, speed_mode="free",
                          speed_m_s=math.nan, speed_m_min=math.nan, step_length=math.nan,
                          step_time=math.nan, cost=math.nan,
                          status="failed at speed free: Maximum_Iterations_Exceeded",
                          success=False, iterations=3000, wall_time_s=9.0, file="")
    else:
        free = SummaryRow(variant=VARIANT, ankle=True, impulse=True, speed_mode="free",
                          speed_m_s=free_m_min / 60.0, speed_m_min=free_m_min,
                          step_length=step, step_time=step / (free_m_min / 60.0), cost=1.5,
                          status="Solve_Succeeded", success=True, iterations=20,
                          wall_time_s=1.0, file=f"gaits/{VARIANT}/speed-free.gait.json")
    return [cold, free]


# -- the rule -------------------------------------------------------------------------------------

@pytest.mark.parametrize(("paper_m_min", "start_m_min"), [
    (11.1, 12.0),    # the five-link biped on uniform 8 + 5 knots: the start it always had
    (13.6, 15.0),    # ... on cosine 8 + 5 knots
    (13.27, 12.0),   # ... on the converged grid
    (73.53, 75.0),   # the seven-link model with feet, cosine 24 + 16 knots
    (74.75, 75.0),   # ... uniform 24 + 16 knots
    (76.4, 75.0),
    (76.6, 78.0),
    (1.7, 3.0),      # a crawl at the step-length bound: never below one step of 3 m/min
    (0.2, 3.0),
])
def test_auto_start_is_the_paper_optimum_rounded_to_3_m_min(paper_m_min: float,
                                                            start_m_min: float) -> None:
    choice = auto_start_speed(_rows(12.0, paper_m_min), VARIANT, max_speed=1.5)
    assert choice.speed * 60.0 == pytest.approx(start_m_min, abs=1e-9)
    assert choice.rule == AUTO_START
    assert choice.paper_optimum == pytest.approx(paper_m_min / 60.0)
    # a multiple of the step, within half a step of the optimum (or the lowest step)
    steps = choice.speed * 60.0 / AUTO_START_STEP_M_MIN
    assert steps == pytest.approx(round(steps), abs=1e-9)
    assert (abs(choice.speed * 60.0 - paper_m_min) <= AUTO_START_STEP_M_MIN / 2 + 1e-9
            or choice.speed * 60.0 == AUTO_START_STEP_M_MIN)
    assert f"{paper_m_min:.2f} m/min" in choice.reason


def test_auto_start_stays_within_the_speed_bound() -> None:
    """An optimum near the upper speed bound that rounds above it starts at the bound."""
    assert auto_start_speed(_rows(12.0, 89.9), VARIANT, max_speed=1.5).speed == 1.5
    assert auto_start_speed(_rows(12.0, 88.6), VARIANT, max_speed=89.0 / 60.0).speed * 60.0 \
        == pytest.approx(89.0)


def test_auto_start_without_a_paper_optimum_is_12_m_min_and_says_why() -> None:
    failed = auto_start_speed(_rows(12.0, None), VARIANT, max_speed=1.5)
    assert failed.speed == START_SPEED and failed.paper_optimum is None
    assert "Maximum_Iterations_Exceeded" in failed.reason
    missing = auto_start_speed([], VARIANT, max_speed=1.5)
    assert missing.speed == START_SPEED and "not solved" in missing.reason
    # another variant's optimum is not this variant's
    other = auto_start_speed(_rows(12.0, 74.0), "plain", max_speed=1.5)
    assert other.speed == START_SPEED


# -- the plan and the settings --------------------------------------------------------------------

def test_auto_start_sweeps(five_link: RobotModel, tmp_path: Path) -> None:
    """With the automatic start (the default) the paper case starts at 12 m/min and every other
    case at the start taken from the paper case's sweep in the folder; the paper case's sweep
    is also the reference sweep."""
    spec = CostStudySpec(models=(five_link,), resting_powers=(1.2,))
    assert spec.start_speed == AUTO_START and spec.auto_start
    with pytest.raises(CostStudyError, match="start_speed = 'auto'.*not solved yet"):
        spec.sweeps()
    paper_dir = tmp_path / "five-link" / "paper"
    paper_dir.mkdir(parents=True)
    write_summary(paper_dir / SUMMARY_FILE, _rows(12.0, 31.4))
    starts = start_choices(spec, tmp_path)
    assert starts["five-link"].speed * 60.0 == pytest.approx(30.0)
    speeds = {s.case.tag: s.spec.speeds[0] * 60.0 for s in spec.sweeps(starts)}
    assert speeds == pytest.approx({"paper": 12.0, "work": 30.0, "metabolic-rest-1.2": 30.0})
    ref = spec.reference_sweep(five_link)
    assert ref.subdir == "five-link/paper" and ref.spec == spec.sweeps(starts)[0].spec
    # a given start is every case's, the paper case's too
    given = CostStudySpec(models=(five_link,), costs=("paper", "work"), start_speed=1.25)
    assert [s.spec.speeds for s in given.sweeps()] == [(1.25,), (1.25,)]
    assert start_choice(given, five_link, tmp_path) == given_start(1.25)


def test_collected_rows_name_each_case_s_own_start(five_link: RobotModel,
                                                   tmp_path: Path) -> None:
    spec = CostStudySpec(models=(five_link,), costs=("paper", "metabolic"),
                         resting_powers=(1.2,))
    for tag, rows in (("paper", _rows(12.0, 73.53)), ("metabolic-rest-1.2", _rows(75.0, 62.48))):
        (tmp_path / "five-link" / tag).mkdir(parents=True)
        write_summary(tmp_path / "five-link" / tag / SUMMARY_FILE, rows)
    by = {r.case: r for r in collect_rows(spec, tmp_path)}
    assert by["paper"].start == "from 12 m/min"
    assert by["metabolic-rest-1.2"].start == "from 75 m/min"
    assert by["metabolic-rest-1.2"].speed_m_min == 62.48


def test_settings_say_which_start_each_model_used(five_link: RobotModel,
                                                   seven_link: RobotModel) -> None:
    spec = CostStudySpec(models=(five_link, seven_link), costs=("metabolic",),
                         resting_powers=(1.2,))
    before = spec.settings()
    assert before["start_rule"] == "auto" and before["start_speed_m_min"] is None
    assert [m["start"] for m in before["models"]] == [None, None]
    five = auto_start_speed(_rows(12.0, 11.1), VARIANT, max_speed=1.5)
    after = spec.settings({"five-link": five})
    start = after["models"][0]["start"]
    assert start["rule"] == "auto" and start["speed_m_min"] == pytest.approx(12.0)
    assert start["paper_optimum_m_min"] == pytest.approx(11.1)
    assert "11.10 m/min" in start["reason"]
    assert after["models"][1]["start"] is None  # not known yet
    json.dumps(after)  # plain data
    given = CostStudySpec(models=(five_link,), start_speed=1.25).settings()
    assert given["start_rule"] == "given" and given["start_speed_m_min"] == pytest.approx(75.0)


def test_knots_by_gait(five_link: RobotModel, seven_link: RobotModel) -> None:
    """Without ``knots`` the paper's walk gets 8 + 5 knots and the heel-toe walk 24 + 16;
    given knots are every model's."""
    spec = CostStudySpec(models=(five_link, seven_link), costs=("paper",))
    assert spec.knots_of(five_link) == DEFAULT_KNOTS["walk"] == (8, 5)
    assert spec.knots_of(seven_link) == DEFAULT_KNOTS["heel-toe"] == (24, 16)
    five, seven = spec.sweeps()
    assert (five.spec.base.knots, seven.spec.base.knots) == ((8, 5), (24, 16))
    assert seven.spec.base.gait == "heel-toe" and seven.formulation == "full"
    # every solve of the study, sweep points and direct solves, has the study's iteration limit
    assert {s.spec.base.max_iter for s in (five, seven)} == {STUDY_MAX_ITER}
    assert seven.direct_task().options.max_iter == STUDY_MAX_ITER
    assert spec.settings()["max_iter"] == STUDY_MAX_ITER
    assert [m["knots"] for m in spec.settings()["models"]] == [[8, 5], [24, 16]]
    fixed = CostStudySpec(models=(five_link, seven_link), costs=("paper",), knots=(16, 6))
    assert {s.spec.base.knots for s in fixed.sweeps()} == {(16, 6)}


@pytest.mark.parametrize("value", ["fast", "", -1.0, 0.0, 6.0, math.inf, True])
def test_bad_start_speeds_are_named(five_link: RobotModel, value: Any) -> None:
    with pytest.raises(CostStudyError, match=r"start_speed = .*must be 'auto' or lie in "
                                             r"\(0, 5\] m/s"):
        CostStudySpec(models=(five_link,), start_speed=value)


# -- the command ----------------------------------------------------------------------------------

class _FakeSweeps:
    """Stands in for the sweeps: records what each was asked to solve and writes the summary
    it would write (the speed-free optimum from ``optima``: (model, case) -> m/min or None)."""

    def __init__(self, optima: dict[tuple[str, str], float | None]) -> None:
        self.optima = optima
        self.calls: list[tuple[str, float, tuple[int, int], str]] = []

    def __call__(self, console: Any, spec: SweepSpec, directory: Path, **kwargs: Any) -> None:
        model, case = directory.parts[-2:]
        start = spec.speeds[0] * 60.0
        self.calls.append((f"{model}/{case}", round(start, 6), tuple(spec.base.knots),
                           spec.base.gait))
        directory.mkdir(parents=True, exist_ok=True)
        write_summary(directory / SUMMARY_FILE, _rows(start, self.optima[(model, case)]))


@pytest.fixture
def fake_study(monkeypatch: pytest.MonkeyPatch) -> _FakeSweeps:
    import gaitopt.cli.cost_study as command
    import gaitopt.study.cost_study as study

    fake = _FakeSweeps({})
    monkeypatch.setattr(command, "run_with_progress", fake)
    monkeypatch.setattr(study, "run_direct_solves", lambda *a, **k: (0, 0, 0))
    monkeypatch.setattr(command, "write_cost_reports", lambda console, d, out: out)
    return fake


def test_cli_two_models_start_each_from_its_paper_optimum(fake_study: _FakeSweeps,
                                                           tmp_path: Path) -> None:
    """``gaitopt study --costs --model five-link --model seven-link`` (defaults): each model's
    paper case first from 12 m/min, its other cases from its own paper optimum rounded to
    3 m/min, each model on its gait's knots; the settings say what was used; a rerun asks the
    same of every sweep (so the sweeps keep their finished points)."""
    fake_study.optima = {
        ("five-link", "paper"): 11.1, ("five-link", "metabolic-rest-1.2"): 27.2,
        ("seven-link", "paper"): 73.53, ("seven-link", "metabolic-rest-1.2"): 62.48}
    out = tmp_path / "costs"
    args = ["study", "--costs", "--cost", "paper", "--cost", "metabolic", "--resting-powers",
            "1.2", "--model", "five-link", "--model", "seven-link", "--workers", "0",
            "-o", str(out)]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert fake_study.calls == [
        ("five-link/paper", 12.0, (8, 5), "walk"),
        ("five-link/metabolic-rest-1.2", 12.0, (8, 5), "walk"),
        ("seven-link/paper", 12.0, (24, 16), "heel-toe"),
        ("seven-link/metabolic-rest-1.2", 75.0, (24, 16), "heel-toe")]
    text = " ".join(result.output.split())
    assert "seven-link: its other cases start at the paper case's speed-free optimum, " \
           "73.53 m/min, rounded to 3 m/min: 75 m/min" in text
    assert "[4/4] seven-link (full): metabolic, resting 1.2 W/kg, from 75 m/min" in text
    settings = json.loads((out / COST_STUDY_FILE).read_text())
    assert settings["start_rule"] == "auto"
    assert [(m["name"], m["start"]["speed_m_min"], m["knots"]) for m in settings["models"]] == [
        ("five-link", 12.0, [8, 5]), ("seven-link", 75.0, [24, 16])]
    rows = {(r.model, r.case): r for r in read_cost_table(out / COST_TABLE_FILE)}
    assert rows[("seven-link", "metabolic-rest-1.2")].start == "from 75 m/min"
    assert rows[("seven-link", "paper")].start == "from 12 m/min"

    first = list(fake_study.calls)
    fake_study.calls.clear()
    again = CliRunner().invoke(cli, args)
    assert again.exit_code == 0, again.output
    assert fake_study.calls == first
    assert json.loads((out / COST_STUDY_FILE).read_text()) == settings


def test_cli_auto_start_without_the_paper_case(fake_study: _FakeSweeps, tmp_path: Path) -> None:
    """``--cost metabolic`` alone: the paper case's sweep still runs first (marked ``[start]``)
    and sets the start, but the table holds only the cases asked for; a failed paper optimum
    leaves the start at 12 m/min, and the settings say why."""
    fake_study.optima = {("seven-link", "paper"): None,
                         ("seven-link", "metabolic-rest-1.2"): 20.0}
    out = tmp_path / "costs"
    result = CliRunner().invoke(cli, ["study", "--cost", "metabolic", "--resting-powers", "1.2",
                                      "--model", "seven-link", "--workers", "0", "-o",
                                      str(out)])
    assert result.exit_code == 0, result.output
    assert [c[:2] for c in fake_study.calls] == [("seven-link/paper", 12.0),
                                                ("seven-link/metabolic-rest-1.2", 12.0)]
    assert "[start] seven-link (full): paper" in " ".join(result.output.split())
    assert [r.case for r in read_cost_table(out / COST_TABLE_FILE)] == ["metabolic-rest-1.2"]
    start = json.loads((out / COST_STUDY_FILE).read_text())["models"][0]["start"]
    assert start["speed_m_min"] == 12.0 and start["paper_optimum_m_min"] is None
    assert "Maximum_Iterations_Exceeded" in start["reason"]


def test_cli_given_start_speed_keeps_working(fake_study: _FakeSweeps, tmp_path: Path) -> None:
    fake_study.optima = {("seven-link", "paper"): 74.0,
                         ("seven-link", "metabolic-rest-1.2"): 62.0}
    out = tmp_path / "costs"
    result = CliRunner().invoke(cli, ["study", "--cost", "paper", "--cost", "metabolic",
                                      "--resting-powers", "1.2", "--model", "seven-link",
                                      "--start-speed", "75m/min", "--knots", "16,10",
                                      "--workers", "0", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert fake_study.calls == [("seven-link/paper", 75.0, (16, 10), "heel-toe"),
                                ("seven-link/metabolic-rest-1.2", 75.0, (16, 10), "heel-toe")]
    settings = json.loads((out / COST_STUDY_FILE).read_text())
    assert settings["start_rule"] == "given" and settings["start_speed_m_min"] == 75.0
    assert settings["models"][0]["start"]["rule"] == "given"


@pytest.mark.parametrize(("value", "words"), [
    ("fast", "--start-speed: speed 'fast'"),
    ("automatic", "--start-speed: speed 'automatic'"),
    ("0m/min", "start_speed = 0.0 m/s: must be 'auto' or lie in (0, 5] m/s"),
])
def test_cli_bad_start_speed_is_a_usage_error(tmp_path: Path, value: str, words: str) -> None:
    out = tmp_path / "costs"
    result = CliRunner().invoke(cli, ["study", "--costs", "--start-speed", value, "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert words in " ".join(result.output.split())
    assert "Traceback" not in result.output and not out.exists()


def test_case_start_of_a_given_speed_is_the_same_for_every_case(five_link: RobotModel) -> None:
    spec = CostStudySpec(models=(five_link,), start_speed=0.5)
    assert {spec.start_of(five_link, c, None) for c in spec.cases} == {0.5}
    auto = CostStudySpec(models=(five_link,))
    assert auto.start_of(five_link, CostCase("paper"), None) == START_SPEED
