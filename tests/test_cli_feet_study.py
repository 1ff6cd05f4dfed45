"""``gaitopt study --model seven-link``: the plan of the study on a model with feet (no solve),
the five-link study's plan unchanged, the convergence passes' choices, and (slow) a solved
study on two speeds."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.cli.study import FEET_STUDY_SPEEDS, STUDY_SPEEDS, study_spec
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.robot import load_model
from gaitopt.study.driver import check_points
from gaitopt.study.executors import BackendError
from gaitopt.study.optima import free_restarts, restart_seeds, restart_spec
from gaitopt.study.plan import ankle_actuators, passive_ankles
from gaitopt.study.summary import SUMMARY_FILE, VARIANTS, SummaryRow, read_summary, variant_flags

GRID = {"knot_spacing": GaitOptions().knot_spacing}


def cold_starts(spec: object) -> list[str]:
    return [k for k, parent in spec.parents.items() if parent is None]  # type: ignore[attr-defined]


def test_the_seven_link_study_walks_heel_to_toe_with_passive_ankles_as_a_variant() -> None:
    spec = study_spec("seven-link", None, GRID)
    assert FEET_STUDY_SPEEDS == "12:120:12"
    assert [round(v * 60, 9) for v in spec.speeds] == [12.0 * k for k in range(1, 11)]
    assert spec.variants == VARIANTS and spec.free_speed
    assert len(spec.points) == 4 * 11
    assert (spec.base.gait, spec.base.formulation, spec.knots) == ("heel-toe", "full", (24, 16))
    # every chain starts at the heel-toe walk's default speed (72.2 m/min: 72 on this grid)
    assert spec.start * 60 == pytest.approx(72.23, abs=0.01)
    assert all(k.endswith("speed-072.00m_min.gait.json") for k in cold_starts(spec))
    model = load_model("seven-link")
    assert ankle_actuators(model) == ("ankle_1", "ankle_2")
    for p in spec.points:
        ankle, _ = variant_flags(p.variant)
        m = spec.model_of(p)
        if ankle:
            assert m is spec.model
        else:  # no ankle actuator, the ankles' damping kept
            assert m.name == "seven-link-passive-ankles"
            assert not ankle_actuators(m) and m.nu == model.nu - 2
            assert m.coordinate_damping == model.coordinate_damping
    check_points(spec)  # every point's options valid for its model: no biped error
    # the check grid: the same points on 36+24 knots
    assert study_spec("seven-link", None, {**GRID, "knots": (36, 24)}).knots == (36, 24)


def test_the_five_link_study_plan_is_the_papers() -> None:
    spec = study_spec("five-link", None, GRID)
    assert STUDY_SPEEDS == "3:60:3"
    assert [round(v * 60, 9) for v in spec.speeds] == [3.0 * k for k in range(1, 21)]
    assert spec.variants == VARIANTS and len(spec.points) == 84
    assert (spec.base.gait, spec.base.formulation, spec.knots) == ("walk", "reduced", (16, 6))
    assert spec.start == 0.2
    assert all(k.endswith("speed-012.00m_min.gait.json") for k in cold_starts(spec))
    assert all(spec.model_of(p) is spec.model for p in spec.points)  # ankle=False does it
    assert passive_ankles(spec.model) is spec.model
    # every point's options are the defaults with the point's fields, as before the feet
    for p in spec.points:
        ankle, impulse = variant_flags(p.variant)
        expected = GaitOptions(knot_spacing="cosine").replace(
            speed=p.speed, ankle=ankle, impulse=impulse, step_length=None, step_time=None,
            single_support_fraction=0.85)
        assert spec.options(p).to_dict() == expected.to_dict()


def test_study_on_seven_link_plans_and_validates_every_point(tmp_path: Path,
                                                              monkeypatch: pytest.MonkeyPatch
                                                              ) -> None:
    """The command gets past the plan and the options' checks (it failed there with 'a biped
    needs exactly two contact points'); the backend is stopped before any solve."""
    def no_backend(**_: object) -> None:
        raise BackendError("no backend in this test")

    monkeypatch.setattr("gaitopt.study.driver.make_backend", no_backend)
    folder = tmp_path / "feet"
    result = CliRunner(env={"COLUMNS": None}).invoke(
        cli, ["study", "--model", "seven-link", "--speeds", "30,60", "-o", str(folder)])
    assert "contact points" not in result.output
    assert "no backend in this test" in result.output, result.output
    assert "heel-toe walk, full coordinates, 24+16 knots, 2 speeds 30-60 m/min" in " ".join(
        result.output.split())
    assert "seven-link-passive-ankles" in result.output
    assert (folder / "sweep.json").exists()


def _row(variant: str, speed: float | None, cost: float, success: bool = True) -> SummaryRow:
    ankle, impulse = variant_flags(variant)
    free = speed is None
    v = 1.0 if free else speed / 60.0  # type: ignore[operator]
    return SummaryRow(variant=variant, ankle=ankle, impulse=impulse,
                      speed_mode="free" if free else "fixed", speed_m_s=v,
                      speed_m_min=v * 60.0, step_length=0.7, step_time=0.7 / v, cost=cost,
                      status="ok", success=success, iterations=10, wall_time_s=1.0,
                      file=f"gaits/{variant}/x.gait.json" if success else "")


def test_a_speed_free_optimum_above_a_fixed_speed_point_is_restarted_from_it() -> None:
    rows = [_row("ankle", 30, 3000.0), _row("ankle", 60, 2000.0), _row("ankle", None, 2100.0),
            _row("plain", 30, 9000.0), _row("plain", None, 8000.0),
            _row("impulse", 30, 5000.0), _row("impulse", None, math.nan, success=False),
            _row("ankle+impulse", 30, math.nan, success=False)]
    chosen = free_restarts(rows, VARIANTS)
    assert sorted(chosen) == ["ankle", "impulse"]  # plain's optimum is below; a+i: no fixed
    assert chosen["ankle"].speed_m_min == pytest.approx(60.0)
    spec = study_spec("seven-link", "30,60", GRID)
    again = restart_spec(spec, "ankle", chosen["ankle"])
    assert [p.key for p in again.points] == ["gaits/ankle/speed-060.00m_min.gait.json",
                                             "gaits/ankle/speed-free.gait.json"]
    assert all(again.parents[p.key] is None for p in again.points)
    assert set(restart_seeds(again, Path("best.gait.json")).values()) == {Path("best.gait.json")}


@pytest.mark.slow
def test_study_on_seven_link_solves_every_point(tmp_path: Path) -> None:
    """One speed (72 m/min, the chains' start), every variant and its speed-free optimum,
    the check grid and the refinement: every point converges (2 minutes on 2 quiet cores)."""
    folder = tmp_path / "feet"
    result = CliRunner(env={"COLUMNS": None}).invoke(
        cli, ["study", "--model", "seven-link", "--speeds", "72", "-o", str(folder)])
    assert result.exit_code == 0, result.output
    rows = read_summary(folder / SUMMARY_FILE)
    assert len(rows) == 8 and all(r.success for r in rows)
    assert (folder / "report" / "report.html").exists()
