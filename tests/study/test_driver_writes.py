"""The driver writes every gait file from what the workers return (workers write nothing):
checked with stand-in workers that return synthetic gaits at once, so no solve is needed."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from gaitopt.gait.record.file import Gait
from gaitopt.robot import load_model
from gaitopt.study.driver import run_sweep
from gaitopt.study.executors import Backend, InlineExecutor
from gaitopt.study.plan import SweepPoint, SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, read_summary, summary_row, variant_flags
from gaitopt.study.sweep_directory import prepare_directory
from gaitopt.study.worker import PointOutcome, PointTask
from tests.viz.synthetic import synthetic_gait

MODEL = load_model("five-link")
K9, K12, K15 = (f"gaits/plain/speed-{v:06.2f}m_min.gait.json" for v in (9, 12, 15))


def stand_in(slots: int, data: Callable[[PointTask, Gait], Any] = lambda t, g: g.to_dict()
             ) -> tuple[Backend, dict[str, Gait]]:
    """A backend whose 'worker' returns a synthetic gait for each point at once (its
    futures are done when submitted), and the gaits it returned, by point key."""
    executor = InlineExecutor()
    made: dict[str, Gait] = {}

    def solve(task: PointTask) -> PointOutcome:
        gait = synthetic_gait(speed=task.options.speed or 0.2)
        made[task.key] = gait
        ankle, impulse = variant_flags(task.variant)
        row = summary_row(gait, ankle=ankle, impulse=impulse, speed_mode=task.speed_mode,
                          file=task.relfile)
        return PointOutcome(key=task.key, row=row, gait=data(task, gait), result=None,
                            warm="none", fell_back=False, stages=1, iterations=42,
                            wall_time_s=0.0, worker="stand-in:0", structures=frozenset())

    backend = Backend(name="stand-in", slots=slots,
                      submit_fn=lambda fn, task: executor.submit(solve, task),
                      close_fn=lambda wait: None)
    return backend, made


def spec_of(*speeds_m_min: float, variants: tuple[str, ...] = ("plain",)) -> SweepSpec:
    return SweepSpec(model=MODEL, speeds=tuple(v / 60 for v in speeds_m_min),
                     variants=variants, free_speed=False)


def test_the_driver_writes_each_returned_gait_as_the_gait_would_save_itself(
        tmp_path: Path) -> None:
    backend, made = stand_in(slots=2)
    report = run_sweep(spec_of(9, 12, 15), tmp_path / "sweep", backend=backend)
    assert (report.counts.succeeded, report.counts.failed) == (3, 0)
    assert set(made) == {K9, K12, K15}
    for key, gait in made.items():
        reference = gait.save(tmp_path / "reference" / key)
        assert (tmp_path / "sweep" / key).read_bytes() == reference.read_bytes()
    for outcome in report.outcomes:  # the gait data is dropped once written
        assert outcome.gait is None and outcome.timings["write_s"] >= 0.0
    rows = read_summary(tmp_path / "sweep" / SUMMARY_FILE)
    assert [r.file for r in rows] == [K9, K12, K15] and all(r.success for r in rows)
    assert not list((tmp_path / "sweep").rglob("*.tmp"))


def test_ctrl_c_writes_every_point_already_returned(tmp_path: Path) -> None:
    backend, made = stand_in(slots=2)  # both cold starts are returned before either is written
    seen: list[str] = []

    def on_point(point: SweepPoint, outcome: PointOutcome, counts: object) -> None:
        seen.append(point.key)
        if len(seen) == 1:
            raise KeyboardInterrupt

    report = run_sweep(spec_of(12, variants=("impulse", "plain")), tmp_path / "sweep",
                       backend=backend, on_point=on_point)
    assert report.interrupted and report.counts.succeeded == 2
    assert sorted(seen) == sorted(made) and len(made) == 2
    rows = read_summary(tmp_path / "sweep" / SUMMARY_FILE)
    assert len(rows) == 2
    for row in rows:
        assert Gait.load(tmp_path / "sweep" / row.file).cost_value == row.cost


def test_a_gait_that_cannot_be_written_fails_its_point_not_the_sweep(tmp_path: Path) -> None:
    spec = spec_of(9, 12, 15)
    folder = tmp_path / "sweep"
    prepare_directory(spec, folder)
    (folder / K12).mkdir(parents=True)  # a folder where the 12 m/min file goes
    backend, _ = stand_in(slots=1, data=lambda task, gait: (
        {"format": "not a gait"} if task.key == K15 else gait.to_dict()))
    report = run_sweep(spec, folder, backend=backend)
    assert (report.counts.succeeded, report.counts.failed) == (1, 2)
    rows = {r.speed_m_min: r for r in read_summary(folder / SUMMARY_FILE)}
    assert rows[9.0].success and Gait.load(folder / K9).success
    for v, error in ((12.0, "IsADirectoryError"), (15.0, "GaitFileError")):
        assert not rows[v].success and rows[v].file == ""
        assert rows[v].status.startswith(f"error: cannot write the gait file: {error}")
    assert (folder / K12).is_dir() and not (folder / K15).exists()
    assert not list(folder.rglob("*.tmp"))
    assert all(o.gait is None for o in report.outcomes)
