"""The walk-run study's plan, table, transitions, findings and report on synthetic rows
(:mod:`gaitopt.study.walk_run`, :mod:`gaitopt.study.walk_run_findings`,
:mod:`gaitopt.viz.walk_run_report`); no solve."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from gaitopt.robot.model import RobotModel
from gaitopt.study.transition import HUMAN_FROUDE_BAND
from gaitopt.study.walk_run import (
    DEFAULT_SPEEDS_M_MIN,
    DEFAULT_SPEEDS_M_MIN_BY_COST,
    TRANSITIONS_FILE,
    WalkRunRow,
    WalkRunSpec,
    WalkRunStudyError,
    branches_of,
    collect_rows,
    cost_curves,
    leg_length_of,
    mark_cheapest,
    read_table,
    transitions,
    write_table,
    write_transitions,
)
from gaitopt.study.walk_run_findings import FINDING_IDS, assess_walk_run
from gaitopt.viz.walk_run_report import write_walk_run_report


def row(branch: str, speed: float, cost: float | None, *, error: float = math.nan,
        model: str = "five-link", cost_name: str = "paper", share: float = 0.9) -> WalkRunRow:
    kind = "run" if branch == "run" else "walk"
    common: dict[str, Any] = {"model": model, "cost": cost_name, "branch": branch, "kind": kind,
                              "speed_m_min": float(speed),
                              "froude": (speed / 60.0) ** 2 / 9.81}
    if cost is None:
        return WalkRunRow(**common, success=False, status="failed at relaxed contact")
    return WalkRunRow(**common, success=True, status="Solve_Succeeded", cost_value=cost,
                      cost_error=error, step_length=0.5, step_time=0.5, first_phase_share=share,
                      file=f"{model}/{cost_name}/{branch}/gaits/x/{speed:g}.gait.json")


def synthetic_rows() -> list[WalkRunRow]:
    """The walk cheaper at 60 and 90 m/min, the run at 120 and 150 (costs linear between:
    the walk's best minus the run is 100, 50, -50, -100); the single-support walk failed at
    150, the walk at 90."""
    return mark_cheapest([
        row("walk", 60, 200.0), row("walk", 90, None), row("walk", 120, 700.0),
        row("walk", 150, 900.0),
        row("walk-single-support", 60, 150.0, error=5.0),
        row("walk-single-support", 90, 300.0, error=5.0),
        row("walk-single-support", 120, 450.0, error=5.0),
        row("walk-single-support", 150, None),
        row("run", 60, 250.0, error=-5.0), row("run", 90, 350.0, error=-5.0),
        row("run", 120, 400.0, error=10.0, share=0.95),
        row("run", 150, 800.0, error=10.0, share=0.8),
    ])


def test_branches_follow_the_models_contacts(five_link: RobotModel,
                                             seven_link: RobotModel) -> None:
    assert [b.name for b in branches_of(five_link)] == ["walk", "walk-single-support", "run"]
    assert [b.name for b in branches_of(seven_link)] == ["heel-toe", "run"]
    assert [b.kind for b in branches_of(seven_link)] == ["walk", "run"]


def test_sweeps_of_the_study(five_link: RobotModel, seven_link: RobotModel) -> None:
    spec = WalkRunSpec(models=(five_link, seven_link), costs=("paper",))
    sweeps = spec.sweeps()
    assert [s[0] for s in sweeps] == ["five-link/paper/walk", "five-link/paper/walk-single-support",
                                      "five-link/paper/run", "seven-link/paper/heel-toe",
                                      "seven-link/paper/run"]
    by_name = {s[0]: s[4] for s in sweeps}
    walk, single, run = (by_name[f"five-link/paper/{b}"]
                         for b in ("walk", "walk-single-support", "run"))
    assert not walk.free_speed and walk.check_grid and walk.base.gait == "walk"
    assert walk.step_lengths == (None,)  # the step length free
    assert single.points[0].single_support == 1.0 and single.variants == ("ankle",)
    assert run.base.gait == "run" and run.variants == ("ankle",)  # a run has no impulse
    assert run.base.single_support_fraction_bounds is not None  # its stance share free
    assert [round(v * 60, 9) for v in walk.speeds] == list(DEFAULT_SPEEDS_M_MIN["walk"])
    heel = by_name["seven-link/paper/heel-toe"]
    assert heel.base.gait == "heel-toe"
    assert [round(v * 60, 9) for v in heel.speeds] == list(DEFAULT_SPEEDS_M_MIN["heel-toe"])
    assert spec.settings()["models"][1]["leg_length_m"] == leg_length_of(seven_link)
    # the metabolic cost on feet takes minutes a solve: its own, shorter default grid
    both = WalkRunSpec(models=(five_link, seven_link))
    assert [round(v * 60, 9) for v in both.speeds_of(seven_link, "metabolic")] == list(
        DEFAULT_SPEEDS_M_MIN_BY_COST[("heel-toe", "metabolic")])
    assert both.speeds_of(five_link, "metabolic") == both.speeds_of(five_link, "paper")
    given = WalkRunSpec(models=(seven_link,), speeds=(0.5, 1.0))
    assert given.speeds_of(seven_link, "metabolic") == (0.5, 1.0)
    knotted = WalkRunSpec(models=(five_link,), costs=("metabolic",), speeds=(0.5, 1.0),
                          knots=(8, 5)).sweeps()[0][4]
    assert knotted.knots == (8, 5) and knotted.base.cost == "metabolic"


@pytest.mark.parametrize(("kwargs", "words"), [
    ({"models": ()}, "models: at least one"),
    ({"costs": ("work",)}, "costs: work; allowed"),
    ({"costs": ("paper", "paper")}, "at most once"),
    ({"costs": ()}, "at least one"),
    ({"speeds": (1.0,)}, "at least two speeds"),
    ({"speeds": (1.0, 0.5)}, "strictly ascending"),
    ({"speeds": (0.0, 0.5)}, "positive"),
    ({"knots": (1, 5)}, "knots: \\(1, 5\\); allowed"),
    ({"knot_spacing": "random"}, "knot_spacing = 'random'"),
])
def test_bad_requests_name_the_setting(five_link: RobotModel, kwargs: dict[str, Any],
                                       words: str) -> None:
    with pytest.raises(WalkRunStudyError, match=words):
        WalkRunSpec(**{"models": (five_link,), **kwargs})


def test_the_cheapest_converged_branch_is_marked_at_each_speed() -> None:
    rows = synthetic_rows()
    cheapest = {(r.speed_m_min, r.branch) for r in rows if r.cheapest}
    assert cheapest == {(60, "walk-single-support"), (90, "walk-single-support"),
                        (120, "run"), (150, "run")}
    assert not any(r.cheapest for r in rows if not r.success)


def test_cost_curves_take_the_cheapest_walk() -> None:
    speeds, walk, walk_e, run, run_e = cost_curves(synthetic_rows(), "five-link", "paper")
    assert [round(v * 60, 9) for v in speeds] == [60, 90, 120, 150]
    assert walk == [150.0, 300.0, 450.0, 900.0] and walk_e[:3] == [5.0, 5.0, 5.0]
    assert math.isnan(walk_e[3])  # the walk at 150 m/min carries no estimate
    assert run == [250.0, 350.0, 400.0, 800.0]


def test_transition_findings_table_and_report(five_link: RobotModel, tmp_path: Path) -> None:
    rows = synthetic_rows()
    spec = WalkRunSpec(models=(five_link,), costs=("paper",), speeds=(1.0, 1.5, 2.0, 2.5))
    (t,) = transitions(spec, rows)
    tr = t.transition
    # walk best - run: D = 100, 50, -50, -100: bracket 90-120 m/min, crossing at 105
    assert tr.kind == "crossing"
    assert (tr.bracket[0] * 60, tr.bracket[1] * 60) == pytest.approx((90.0, 120.0), rel=1e-12)
    assert tr.speed * 60 == pytest.approx(105.0, rel=1e-12)
    # errors |5| + |-5| at 90 and |5| + |10| at 120: D 50 +- 10, -50 +- 15
    assert tr.interval[0] * 60 == pytest.approx(90 + 30 * 40 / 105, rel=1e-12)
    assert tr.interval[1] * 60 == pytest.approx(90 + 30 * 60 / 95, rel=1e-12)
    assert t.froude == pytest.approx((105 / 60) ** 2 / (9.81 * 1.0), rel=1e-12)
    findings = assess_walk_run(rows, [t])["five-link / paper"]
    assert [f.id for f in findings.items] == list(FINDING_IDS)
    assert findings["walk.low_speed"].holds is True
    assert findings["run.high_speed"].holds is True
    inside = HUMAN_FROUDE_BAND[0] <= t.froude <= HUMAN_FROUDE_BAND[1]
    assert findings["transition.people"].holds is inside
    assert "105.0 m/min" in findings["transition.people"].evidence
    # the cheapest run at 120 m/min stands 0.95 of the step: on the bound
    assert findings["run.flight"].holds is False
    assert "on the bound at 120 m/min" in findings["run.flight"].evidence

    table = write_table(tmp_path, rows)
    back = read_table(table)
    assert [(r.branch, r.speed_m_min, r.success, r.cheapest) for r in back] == [
        (r.branch, r.speed_m_min, r.success, r.cheapest) for r in rows]
    assert all((a.cost_value == b.cost_value) or (math.isnan(a.cost_value)
                                                  and math.isnan(b.cost_value))
               for a, b in zip(back, rows, strict=True))
    text = write_transitions(tmp_path, [t]).read_text()
    assert text.splitlines()[1].startswith("five-link,paper,crossing,90.0,120.0,105.0,")
    assert (tmp_path / TRANSITIONS_FILE).exists()

    info = write_walk_run_report(rows, [t], tmp_path / "report", svg=False)
    page = info.html.read_text()
    assert "walk.low_speed" in page and "105.0" in page and "failed at relaxed contact" in page
    assert info.figures[0].stat().st_size > 10_000


def test_findings_when_the_walk_is_cheaper_everywhere(five_link: RobotModel) -> None:
    rows = mark_cheapest([row("walk", 60, 100.0), row("walk", 90, 200.0),
                          row("run", 60, 150.0), row("run", 90, 250.0)])
    spec = WalkRunSpec(models=(five_link,), costs=("paper",))
    (t,) = transitions(spec, rows)
    assert t.transition.kind == "walk"
    findings = assess_walk_run(rows, [t])["five-link / paper"]
    assert findings["walk.low_speed"].holds is True
    assert findings["run.high_speed"].holds is False
    assert findings["transition.people"].holds is False
    assert "no transition within the grid" in findings["transition.people"].evidence
    assert findings["run.flight"].holds is None  # the run is never the cheapest


def test_findings_cannot_tell_without_common_speeds(five_link: RobotModel) -> None:
    rows = mark_cheapest([row("walk", 60, 100.0), row("run", 60, None),
                          row("run", 90, 250.0), row("walk", 90, None)])
    (t,) = transitions(WalkRunSpec(models=(five_link,), costs=("paper",)), rows)
    findings = assess_walk_run(rows, [t])["five-link / paper"]
    assert [f.holds for f in findings.items] == [None, None, None, None]


def test_a_missing_sweep_gives_not_solved_rows(five_link: RobotModel, tmp_path: Path) -> None:
    spec = WalkRunSpec(models=(five_link,), costs=("paper",), speeds=(0.5, 1.0))
    rows = collect_rows(spec, tmp_path)
    assert len(rows) == 6 and {r.status for r in rows} == {"not solved"}
    assert not any(r.success or r.cheapest for r in rows)


def test_bad_table_names_line_and_column(tmp_path: Path) -> None:
    rows = synthetic_rows()
    path = write_table(tmp_path, rows)
    lines = path.read_text().splitlines()
    lines[2] = lines[2].replace("five-link,paper,walk,walk,90.0", "five-link,paper,walk,walk,x")
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(WalkRunStudyError, match="line 3: column speed_m_min"):
        read_table(path)
    path.write_text("model,cost\n")
    with pytest.raises(WalkRunStudyError, match="missing columns"):
        read_table(path)


def test_check_grid_is_a_setting_of_the_sweep_only_when_on(five_link: RobotModel) -> None:
    from dataclasses import replace

    from gaitopt.study.plan import sweep_settings

    sweep = WalkRunSpec(models=(five_link,), costs=("paper",)).sweeps()[0][4]
    assert sweep_settings(sweep)["check_grid"] is True
    # a sweep without it keeps the settings (and sweep.json) it always had
    assert "check_grid" not in sweep_settings(replace(sweep, check_grid=False))
