"""``gaitopt sweep``, ``report``, ``animate`` and ``study`` through click's CliRunner."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import pytest
from click.testing import CliRunner
from PIL import Image

from gaitopt.cli import UserError, cli
from gaitopt.cli.report import sweep_dirs
from gaitopt.cli.study import parse_speeds, parse_variants
from gaitopt.gait.record.file import Gait
from gaitopt.robot import load_model
from gaitopt.study.grid_error import grid_error
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, VARIANTS, read_summary
from gaitopt.study.sweep_directory import prepare_directory
from tests.viz.synthetic import synthetic_gait, synthetic_sweep


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner(env={"COLUMNS": None})


def test_speed_ranges_are_in_m_per_min_with_the_stop_included() -> None:
    speeds = parse_speeds("3:60:3")
    assert len(speeds) == 20
    assert speeds[0] == pytest.approx(0.05) and speeds[-1] == pytest.approx(1.0)
    assert [round(v * 60, 6) for v in parse_speeds("12, 3:9:3,6,45m/min")] == [
        3, 6, 9, 12, 45]
    assert [round(v * 60, 9) for v in parse_speeds("0.3:0.9:0.3")] == [0.3, 0.6, 0.9]


@pytest.mark.parametrize(("text", "message"), [
    ("60:3:3", "needs start <= stop and step > 0"),
    ("3:60:0", "needs start <= stop and step > 0"),
    ("3:60", "must be a speed or start:stop:step"),
    ("fast", "'fast' is not a speed in m/min"),
    ("-3,6", "must be > 0 m/min, got -3"),
    ("0:12:3", "must be > 0 m/min, got 0"),
    ("", "no speed given"),
    ("1:100000:1", "at most"),
    ("nan", "must be finite"),
])
def test_bad_speed_grids_name_the_option(text: str, message: str) -> None:
    with pytest.raises(UserError, match=message) as info:
        parse_speeds(text)
    assert "--speeds" in str(info.value.message)


def test_variants() -> None:
    assert parse_variants("all") == VARIANTS
    assert parse_variants("plain, ankle") == ("ankle", "plain")
    with pytest.raises(UserError, match="unknown variant 'walking'.*ankle\\+impulse"):
        parse_variants("ankle,walking")


@pytest.mark.parametrize(("args", "message"), [
    (["--speeds", "60:3:3"], "--speeds: range '60:3:3' needs start <= stop"),
    (["--variants", "ankle,hopping"], "--variants: unknown variant 'hopping'"),
    (["--step-length", "0"], "--step-length: '0' must be > 0 m"),
    (["--single-support", "1.5"], "--single-support: '1.5' must lie in \\(0, 1\\]"),
    (["--knots", "8;5"], "--knots"),
    (["--speeds", "12,150", "--step-time", "1"], "150.00 m/min: targets.step_time = 1 s"),
    (["--step-length", "2", "--speeds", "12"], "step_length = 2 m: longer than the legs"),
    (["--model", "no-such-model.yaml"], "no-such-model.yaml"),
])
def test_sweep_refuses_bad_input_before_solving(runner: CliRunner, tmp_path: Path,
                                                args: list[str], message: str) -> None:
    result = runner.invoke(cli, ["sweep", "-o", str(tmp_path / "s"), *args])
    assert result.exit_code == 2, result.output
    assert re.search(message, result.output), result.output
    assert "Traceback" not in result.output
    assert not (tmp_path / "s" / SUMMARY_FILE).exists()


def test_sweep_refuses_a_directory_made_with_other_settings(runner: CliRunner,
                                                            tmp_path: Path) -> None:
    folder = tmp_path / "s"
    prepare_directory(SweepSpec(model=load_model("five-link"), speeds=(0.1, 0.2)), folder)
    result = runner.invoke(cli, ["sweep", "-o", str(folder), "--speeds", "6,12",
                                 "--variants", "plain"])
    assert result.exit_code == 2
    assert "holds a sweep made with other settings" in result.output
    assert "variants: directory has ['ankle+impulse', 'ankle', 'impulse', 'plain'], this " \
           "run asks ['plain']" in " ".join(result.output.split())
    assert not (folder / SUMMARY_FILE).exists()


def test_sweep_prints_a_line_per_point_and_writes_the_summary(runner: CliRunner,
                                                              tmp_path: Path) -> None:
    folder = tmp_path / "s"
    args = ["sweep", "-o", str(folder), "--speeds", "12,15", "--variants", "plain",
            "--no-free", "--workers", "0"]
    result = runner.invoke(cli, args)
    assert result.exit_code == 0, result.output
    out = result.output
    assert "2 points, 0 kept from an earlier run, 2 to solve on this process" in out
    lines = [line for line in out.splitlines() if line.startswith("ok ")]
    assert len(lines) == 2
    rows = {r.speed_m_min: r for r in read_summary(folder / SUMMARY_FILE)}
    for line in lines:
        speed = float(line.split()[2])
        assert re.search(rf"cost +{rows[speed].cost:.3f} +step {rows[speed].step_length:.4f} m"
                         rf" +(Solve_Succeeded|Solved_To_Acceptable_Level) +it +\d+ +[\d.]+ s",
                         line), line
    assert lines[0].split()[2] == "12.00" and lines[0].endswith("cold")
    assert lines[1].endswith("warm")
    assert "done in" in out and "2 solved, 0 failed, 0 kept" in out
    again = runner.invoke(cli, args)
    assert again.exit_code == 0 and "2 kept from an earlier run, 0 to solve" in again.output


def test_report_prints_where_it_is_and_the_findings(runner: CliRunner, tmp_path: Path) -> None:
    synthetic_sweep(tmp_path / "sweep", speeds_m_min=(3, 6, 12, 24, 36, 50), n_samples=21)
    result = runner.invoke(cli, ["report", str(tmp_path / "sweep"), "-o", str(tmp_path / "r")])
    assert result.exit_code == 0, result.output
    assert f"report: {tmp_path / 'r' / 'report.html'} (20 figure files" in result.output
    assert (tmp_path / "r" / "report.html").stat().st_size > 10000
    assert (tmp_path / "r" / "fig3_energy.png").exists()
    assert "[holds] The energy-optimal walk is much slower" in result.output
    assert "about 12 m/min.  (optimum.speed)" in result.output  # each finding's stable id
    assert "Energy-optimal walk per variant" in result.output


def test_report_errors(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(cli, ["report", str(tmp_path / "none")])
    assert result.exit_code == 2 and "no such directory" in result.output
    (tmp_path / "empty").mkdir()
    result = runner.invoke(cli, ["report", str(tmp_path / "empty")])
    assert result.exit_code == 2 and "no sweep here" in result.output
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / SUMMARY_FILE).write_text("variant,cost\nplain,1\n")
    result = runner.invoke(cli, ["report", str(tmp_path / "bad")])
    assert result.exit_code == 2 and "missing columns" in result.output


def test_nested_sweeps_are_reported_one_by_one(tmp_path: Path) -> None:
    for tag in ("single-support-0.85_step-free", "single-support-1_step-free"):
        synthetic_sweep(tmp_path / tag, speeds_m_min=(12,), gaits=False)
    assert [p.name for p in sweep_dirs(tmp_path)] == ["single-support-0.85_step-free",
                                                      "single-support-1_step-free"]
    assert sweep_dirs(tmp_path / "single-support-1_step-free") == [
        tmp_path / "single-support-1_step-free"]


def test_animate_writes_a_real_time_gif(runner: CliRunner, tmp_path: Path) -> None:
    gait = synthetic_gait(speed=0.3, step_length=0.15, n_samples=31)
    gait.save(tmp_path / "g.gait.json")
    out = tmp_path / "walk.gif"
    result = runner.invoke(cli, ["animate", str(tmp_path / "g.gait.json"), "-o", str(out),
                                 "--steps", "2", "--fps", "10"])
    assert result.exit_code == 0, result.output
    frames = int(re.search(r"\((\d+) frames", result.output).group(1))  # type: ignore[union-attr]
    with Image.open(out) as image:
        assert image.n_frames == frames
    assert frames == pytest.approx(2 * gait.step_time * 10, abs=1.01)


def test_animate_errors(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(cli, ["animate", str(tmp_path / "missing.gait.json")])
    assert result.exit_code == 2 and "no such file" in result.output
    synthetic_gait(n_samples=21).save(tmp_path / "g.gait.json")
    result = runner.invoke(cli, ["animate", str(tmp_path / "g.gait.json"), "-o",
                                 str(tmp_path / "walk.avi")])
    assert result.exit_code == 2 and "unsupported animation file type '.avi'" in result.output
    result = runner.invoke(cli, ["animate", str(tmp_path / "g.gait.json"), "--fps", "0"])
    assert result.exit_code == 2 and "--fps" in result.output


@pytest.mark.slow
def test_study_writes_the_report_and_an_animation(runner: CliRunner, tmp_path: Path) -> None:
    folder = tmp_path / "study"
    result = runner.invoke(cli, ["study", "-o", str(folder), "--speeds", "9,12,15",
                                 "--workers", "0"])
    assert result.exit_code == 0, result.output
    assert (folder / "report" / "report.html").exists()
    assert (folder / "report" / "optimal-walk.gif").exists()
    rows = read_summary(folder / SUMMARY_FILE)
    assert len(rows) == 16 and all(r.success for r in rows)
    assert f"Open {folder / 'report' / 'report.html'}" in result.output
    # The same points on the check grid, and the grid statements they give.
    check = read_summary(folder / "check-grid" / SUMMARY_FILE)
    assert len(check) == 16 and all(r.success for r in check)
    page = (folder / "report" / "report.html").read_text(encoding="utf-8")
    assert "Grid: 16+6 cosine-spaced knots, control model jumps" in page
    assert "at 12 fixed-speed points, 4 speed-free optima): cost within" in page
    assert "on the check grid speed" in " ".join(result.output.split())
    # The points whose estimate exceeds 1 % are re-solved on 36+12 and reported from there.
    # (here the speed-free optima: their speeds move by 0.1 m/min, 3 x that is over 1 %)
    again = read_summary(folder / "refine-grid" / SUMMARY_FILE)
    assert again and all(r.success for r in again)
    assert list(Gait.load(folder / "refine-grid" / again[0].file).options["knots"]) == [36, 12]
    assert "36+12 knots at the" in page and f"refine-grid/{again[0].file}" in page
    # After the refinement levels every figure is within 1 % by its estimate.
    errors = grid_error(folder, rows)
    assert errors is not None and len(errors.points) == 16
    assert all(p.relative <= 0.01 for p in errors.points)


def test_sweep_passes_the_problem_options_to_every_point(runner: CliRunner,
                                                         tmp_path: Path) -> None:
    """--formulation, --cost, --resting-power, --control-model and --knot-spacing reach every
    gait."""
    for name, args, expected in (
            ("full", ["--formulation", "full", "--control-model", "jumps"],
             {"formulation": "full", "control_model": "jumps", "cost": "paper",
              "knot_spacing": "cosine"}),  # the default spacing
            ("metabolic", ["--cost", "metabolic", "--resting-power", "2.0",
                           "--knot-spacing", "uniform"],
             {"formulation": "reduced", "cost": "metabolic", "resting_power": 2.0,
              "knot_spacing": "uniform"})):
        folder = tmp_path / name
        result = runner.invoke(cli, ["sweep", "-o", str(folder), "--speeds", "12,15",
                                     "--variants", "ankle", "--no-free", "--workers", "0",
                                     *args])
        assert result.exit_code == 0, result.output
        gaits = sorted(folder.rglob("*.gait.json"))
        assert len(gaits) == 2
        for path in gaits:
            options = Gait.load(path).options
            assert {k: options[k] for k in expected} == expected


def test_the_check_sweep_with_feet_starts_each_point_from_the_same_point(tmp_path: Path) -> None:
    """With feet every fixed-speed check-grid point is seeded from the study's gait of the
    same point (no continuation in speed), and only where that gait exists; each speed-free
    optimum continues from its group's point at the start speed; every point with ankle
    torques and the impulse from the same check point with ankle torques only. The
    five-link walk keeps its chains, each from a cold start."""
    from gaitopt.cli.study import check_sweep, study_spec

    feet = study_spec("seven-link", "24,48,72", {"knots": (36, 24)})
    assert feet.continuation
    for key in [p.key for p in feet.points]:  # the study's gaits of every point
        (tmp_path / key).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / key).write_text("{}", encoding="utf-8")
    (tmp_path / feet.points[0].key).unlink()  # one point failed in the study: no gait
    check, seeds = check_sweep(feet, tmp_path)
    assert not check.continuation
    assert [p.key for p in check.points] == [p.key for p in feet.points]
    fixed = [p for p in check.points if p.speed is not None]
    free = [p for p in check.points if p.speed is None]
    assert len(free) == len(check.variants) and len(fixed) == 3 * len(check.variants)
    twin = {p.key: replace(p, variant="ankle").key for p in check.points
            if p.variant == "ankle+impulse"}
    assert all(check.parents[p.key] == twin.get(p.key) for p in fixed)
    for p in free:  # from the point at the start speed (72 m/min) of its variant
        if p.key in twin:
            assert check.parents[p.key] == twin[p.key]
            continue
        parent = next(q for q in fixed if q.key == check.parents[p.key])
        assert parent.variant == p.variant and parent.speed == pytest.approx(1.2)
    assert seeds == {p.key: tmp_path / p.key for p in fixed[1:] if p.key not in twin}
    assert feet.points[0].key not in seeds

    walk = study_spec("five-link", "6,12", {"knots": (24, 8)})
    check, seeds = check_sweep(walk, tmp_path)
    assert check is walk and seeds == {}


def test_the_study_with_feet_starts_its_impulse_chains_from_the_variants_without() -> None:
    """With feet the two impulse variants' chains start from the variants without the
    impulse (two cold starts instead of four, each 22-45 s on the seven-link); the five-link
    study keeps four cold starts, as the paper's."""
    from gaitopt.cli.study import study_spec

    feet = study_spec("seven-link", "24,48,72", {"knots": (24, 16)})
    cold = {p.variant for p in feet.points if feet.parents[p.key] is None}
    assert cold == {"ankle", "plain"}
    walk = study_spec("five-link", "6,12", {"knots": (16, 6)})
    assert not walk.impulse_from_no_impulse
    assert {p.variant for p in walk.points if walk.parents[p.key] is None} == set(VARIANTS)
    # the cold starts with feet leave their check grids to the study's check sweep
    assert not feet.check_cold and walk.check_cold


def test_a_failed_point_of_a_sweep_without_chains_restarts_from_its_nearest_neighbour(
        tmp_path: Path) -> None:
    """The rerun of a check sweep with feet starts a point without a gait file from the
    nearest converged fixed-speed point of its variant, never from another variant's."""
    from gaitopt.cli.study import check_sweep, neighbour_seeds, study_spec

    check, _ = check_sweep(study_spec("seven-link", "24,48,72", {"knots": (36, 24)}), tmp_path)
    by = {(p.variant, None if p.speed is None else round(p.speed * 60.0)): p.key
          for p in check.points}
    missing = {("plain", 24), ("plain", 48), ("ankle", 72), ("ankle", None)}
    for key in set(by) - missing:
        (tmp_path / by[key]).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / by[key]).write_text("{}", encoding="utf-8")
    seeds = neighbour_seeds(check, tmp_path)
    assert seeds == {by["plain", 24]: tmp_path / by["plain", 72],
                     by["plain", 48]: tmp_path / by["plain", 72],
                     by["ankle", 72]: tmp_path / by["ankle", 48],
                     by["ankle", None]: tmp_path / by["ankle", 48]}
