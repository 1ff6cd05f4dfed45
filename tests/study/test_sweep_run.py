"""Sweeps solved in this process (``workers=0``): the summary, warm starts, failures, resume.

All points use the no-ankle variants, which share one transcription: it is built once per
test process and reused, so these tests cost a few solves each.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest

from gaitopt.gait.record.file import Gait
from gaitopt.robot import load_model
from gaitopt.study.driver import SweepReport, run_sweep
from gaitopt.study.plan import SETTINGS_FILE, SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, read_summary
from gaitopt.study.sweep_directory import SweepSettingsError, directory_lock, scan_directory

MODEL = load_model("five-link")
K9, K12, K15 = (f"gaits/plain/speed-{v:06.2f}m_min.gait.json" for v in (9, 12, 15))
KFREE = "gaits/plain/speed-free.gait.json"


def plain_spec(*speeds_m_min: float, free: bool = True) -> SweepSpec:
    return SweepSpec(model=MODEL, speeds=tuple(v / 60 for v in speeds_m_min),
                     variants=("plain",), free_speed=free)


@pytest.fixture(scope="module")
def swept(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, SweepReport]:
    folder = tmp_path_factory.mktemp("sweep") / "plain"
    return folder, run_sweep(plain_spec(9, 12, 15), folder, workers=0)


def mtimes(folder: Path) -> dict[str, int]:
    return {str(p.relative_to(folder)): p.stat().st_mtime_ns
            for p in folder.rglob("*.gait.json")}


def test_summary_rows_agree_with_the_gait_files(swept: tuple[Path, SweepReport]) -> None:
    folder, report = swept
    assert report.counts.succeeded == 4 and report.counts.failed == 0
    rows = read_summary(folder / SUMMARY_FILE)
    assert [(r.speed_mode, r.speed_m_min if r.speed_mode == "fixed" else None)
            for r in rows] == [("fixed", 9.0), ("fixed", 12.0), ("fixed", 15.0), ("free", None)]
    for row in rows:
        gait = Gait.load(folder / row.file)
        assert row.success and gait.success and row.variant == "plain"
        assert (row.ankle, row.impulse) == (False, False)
        assert gait.options["ankle"] is False and gait.options["impulse"] is False
        assert row.cost == gait.cost_value and row.step_length == gait.step_length
        assert row.speed_m_s == gait.speed
        assert row.speed_m_min == pytest.approx(60 * gait.speed, rel=1e-12)
        assert row.step_time == pytest.approx(gait.step_length / gait.speed, rel=1e-9)
        assert row.iterations == gait.solver["iterations"]
        if row.speed_mode == "fixed":
            assert gait.speed == pytest.approx(row.speed_m_min / 60, abs=1e-7)
    # the speed-free walk is the optimum: no fixed-speed walk is cheaper
    free = rows[-1]
    assert all(free.cost <= r.cost * (1 + 1e-6) for r in rows[:-1])
    assert 9.0 < free.speed_m_min < 15.0
    assert (folder / SETTINGS_FILE).exists()


def test_points_are_warm_started_from_their_neighbours_results(
        swept: tuple[Path, SweepReport]) -> None:
    _, report = swept
    how = {o.key: o.warm for o in report.outcomes}
    assert how == {K12: "none", K9: "result", K15: "result", KFREE: "result"}
    assert not any(o.fell_back for o in report.outcomes)
    # the cold start was solved first; its neighbours after it
    assert report.outcomes[0].key == K12
    warm_iterations = [o.iterations for o in report.outcomes if o.warm == "result"]
    assert max(warm_iterations) < report.outcomes[0].iterations


def test_rerun_keeps_every_finished_point(swept: tuple[Path, SweepReport]) -> None:
    folder, _ = swept
    before, rows = mtimes(folder), read_summary(folder / SUMMARY_FILE)
    again = run_sweep(plain_spec(9, 12, 15), folder, workers=0)
    assert (again.counts.kept, again.counts.to_solve) == (4, 0)
    assert again.outcomes == ()
    assert mtimes(folder) == before
    assert read_summary(folder / SUMMARY_FILE) == rows


def test_a_directory_of_other_settings_is_refused(swept: tuple[Path, SweepReport]) -> None:
    folder, _ = swept
    with pytest.raises(SweepSettingsError, match=r"other settings.*speeds_m_min: directory "
                                                 r"has \[9\.0, 12\.0, 15\.0\], this run asks "
                                                 r"\[9\.0, 12\.0\]"):
        run_sweep(plain_spec(9, 12), folder, workers=0)
    with pytest.raises(SweepSettingsError, match="free_speed"):
        run_sweep(plain_spec(9, 12, 15, free=False), folder, workers=0)


def test_a_running_sweep_locks_its_directory(swept: tuple[Path, SweepReport]) -> None:
    folder, _ = swept
    with directory_lock(folder), pytest.raises(SweepSettingsError, match="another sweep"):
        run_sweep(plain_spec(9, 12, 15), folder, workers=0)


def test_resume_repairs_a_lost_summary_a_corrupt_file_and_write_leftovers(
        swept: tuple[Path, SweepReport], tmp_path: Path) -> None:
    source, _ = swept
    folder = tmp_path / "copy"
    shutil.copytree(source, folder)
    rows = read_summary(folder / SUMMARY_FILE)
    (folder / SUMMARY_FILE).unlink()
    (folder / K15).write_text('{"format": "gaitopt.gait", "vers')  # a torn write
    leftover = folder / "gaits/plain/.speed-018.00m_min.gait.json.x1y2.tmp"
    leftover.write_text("partial")
    kept = {k: (folder / k).stat().st_mtime_ns for k in (K9, K12, KFREE)}
    report = run_sweep(plain_spec(9, 12, 15), folder, workers=0)
    assert (report.counts.kept, report.counts.succeeded) == (3, 1)
    assert [o.key for o in report.outcomes] == [K15]
    assert report.outcomes[0].warm == "file"  # from the kept 12 m/min gait file
    assert any(K15 in note and "unreadable" in note for note in report.notes)
    assert not leftover.exists()
    assert {k: (folder / k).stat().st_mtime_ns for k in kept} == kept
    again = read_summary(folder / SUMMARY_FILE)
    assert [r for r in again if r.file != K15] == [r for r in rows if r.file != K15]
    assert Gait.load(folder / K15).success


def test_a_failed_point_is_recorded_as_failed_then_solved_on_resume(tmp_path: Path) -> None:
    folder = tmp_path / "fail"
    spec = plain_spec(6, 9, 12, free=False)
    k6 = "gaits/plain/speed-006.00m_min.gait.json"
    report = run_sweep(spec, folder, workers=0, fail_points={K9})
    assert (report.counts.succeeded, report.counts.failed) == (2, 1)
    rows = {r.speed_m_min: r for r in read_summary(folder / SUMMARY_FILE)}
    failed = rows[9.0]
    assert not failed.success and failed.file == ""
    assert failed.status.startswith("failed at ") and "Maximum_Iterations" in failed.status
    assert math.isnan(failed.cost) and math.isnan(failed.step_length)
    assert failed.speed_m_s == pytest.approx(0.15)
    assert not (folder / K9).exists()
    assert rows[6.0].success and rows[12.0].success
    # 6 m/min continued from what 9 m/min was given: the 12 m/min Result
    by_key = {o.key: o for o in report.outcomes}
    assert by_key[k6].warm == "result" and not by_key[k6].fell_back

    scan = scan_directory(spec, folder)  # what a resume starts from
    assert set(scan.kept) == {k6, K12} and set(scan.old_failed) == {K9}
    assert scan.old_failed[K9] == failed

    kept = mtimes(folder)
    resumed = run_sweep(spec, folder, workers=0)
    assert (resumed.counts.kept, resumed.counts.to_solve) == (2, 1)
    assert [o.key for o in resumed.outcomes] == [K9]
    assert all(r.success for r in read_summary(folder / SUMMARY_FILE))
    assert {k: v for k, v in mtimes(folder).items() if k != K9} == kept



def test_files_and_settings_written_before_an_option_existed_are_kept(
        swept: tuple[Path, SweepReport]) -> None:
    """A gait file or sweep.json written before an option was added (step_time,
    multistart) lacks it; it was solved with the option's default, so a resume keeps it."""
    import dataclasses

    from gaitopt.study.plan import (
        settings_differences,
        sweep_settings,
        with_option_defaults,
    )
    from gaitopt.study.worker import gait_file_matches

    folder, _ = swept
    spec = plain_spec(9, 12, 15)
    gait = Gait.load(folder / K12)
    point = next(p for p in spec.points if p.key == K12)
    old = {k: v for k, v in gait.options.items() if k not in ("step_time", "multistart")}
    assert gait_file_matches(dataclasses.replace(gait, options=old), MODEL,
                             spec.options(point)) == ""
    changed = dict(old, multistart=True)
    assert "multistart" in gait_file_matches(dataclasses.replace(gait, options=changed), MODEL,
                                             spec.options(point))
    settings = sweep_settings(spec)
    older = dict(settings, options={k: v for k, v in settings["options"].items()
                                    if k != "multistart"})
    assert settings_differences(older, settings)  # without the defaults: a difference
    assert settings_differences(with_option_defaults(older), settings) == []


def test_points_without_continuation_start_from_their_seed_files(
        swept: tuple[Path, SweepReport], tmp_path: Path) -> None:
    """The refinement sweep's way (``continuation=False`` and ``seeds``): every point starts
    from its own seed file and converges to the same optimum as the chain did."""
    from dataclasses import replace

    folder, _ = swept
    spec = replace(plain_spec(9, 15, free=False), continuation=False)
    assert spec.parents == {K9: None, K15: None}
    report = run_sweep(spec, tmp_path / "seeded", workers=0,
                       seeds={K9: folder / K9, K15: folder / K15})
    assert {o.key: o.warm for o in report.outcomes} == {K9: "file", K15: "file"}
    assert not any(o.fell_back for o in report.outcomes)
    for key in (K9, K15):
        assert Gait.load(tmp_path / "seeded" / key).cost_value == pytest.approx(
            Gait.load(folder / key).cost_value, rel=1e-5)
    saved = (tmp_path / "seeded" / SETTINGS_FILE).read_text(encoding="utf-8")
    assert '"continuation": false' in saved
