"""The same sweep on a Dask cluster (a LocalCluster of two single-threaded processes), also
with workers that cannot see the sweep directory (no shared disk): the driver writes every
file."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from gaitopt.gait.record.file import Gait
from gaitopt.robot import load_model
from gaitopt.study.driver import run_sweep
from gaitopt.study.plan import SweepSpec
from gaitopt.study.summary import SUMMARY_FILE, read_summary

distributed = pytest.importorskip("distributed")


def test_sweep_runs_on_a_dask_cluster(tmp_path: Path) -> None:
    spec = SweepSpec(model=load_model("five-link"), speeds=(0.2, 0.25),
                     variants=("impulse", "plain"), free_speed=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        worker_pids = set(client.run(os.getpid).values())
        report = run_sweep(spec, tmp_path / "dask", scheduler=cluster.scheduler_address)
    # every point ran in a worker process of the cluster, none in this process
    ran_in = {int(o.worker.rsplit(":", 1)[1]) for o in report.outcomes}
    assert ran_in <= worker_pids and os.getpid() not in ran_in
    assert (report.counts.succeeded, report.counts.failed) == (4, 0)
    how = {o.key: o.warm for o in report.outcomes}
    assert how["gaits/plain/speed-015.00m_min.gait.json"] == "result"
    assert how["gaits/plain/speed-012.00m_min.gait.json"] == "none"
    rows = read_summary(tmp_path / "dask" / SUMMARY_FILE)
    assert len(rows) == 4 and all(r.success for r in rows)
    for row in rows:
        gait = Gait.load(tmp_path / "dask" / row.file)
        assert gait.cost_value == row.cost
        assert gait.speed == pytest.approx(row.speed_m_s)


# -- workers that cannot see the sweep directory --------------------------------------------

#: Paths (under the forbidden root) a worker process tried to open, make, list or rename.
_TOUCHED: list[str] = []
_FILE_EVENTS = ("open", "os.mkdir", "os.rename", "os.remove", "os.listdir", "os.scandir",
                "os.chmod", "os.truncate")


def _forbid(root: str) -> None:
    """In a worker process: any file access under ``root`` raises PermissionError (and is
    recorded), as on a cluster whose workers do not mount the driver's disk."""
    def hook(event: str, args: tuple[object, ...]) -> None:
        if event not in _FILE_EVENTS:
            return
        for arg in args[:2]:
            if isinstance(arg, str | bytes | os.PathLike):
                path = os.path.abspath(os.fsdecode(arg))
                if path == root or path.startswith(root + os.sep):
                    _TOUCHED.append(f"{event} {path}")
                    raise PermissionError(f"{path}: not visible from this worker")
    sys.addaudithook(hook)


def _worker_view(relative: str, absolute: str) -> dict[str, object]:
    """What a worker sees of the sweep directory: its working directory, whether the
    driver's relative sweep path exists from there, whether reading the real one is refused."""
    try:
        Path(absolute, "sweep.json").read_bytes()
        refused = False
    except PermissionError:
        refused = True
    _TOUCHED.clear()  # the probe's own attempt is not the sweep's
    return {"cwd": os.getcwd(), "relative_exists": Path(relative).exists(), "refused": refused}


def _touched() -> list[str]:
    return list(_TOUCHED)


def test_dask_workers_need_no_shared_disk(tmp_path: Path,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    worker_home, driver_home = tmp_path / "worker-side", tmp_path / "driver-side"
    worker_home.mkdir()
    driver_home.mkdir()
    spec = SweepSpec(model=load_model("five-link"), speeds=(0.2, 0.25), variants=("plain",),
                     free_speed=False)
    k12, k15 = (f"gaits/plain/speed-{v:06.2f}m_min.gait.json" for v in (12, 15))
    monkeypatch.chdir(worker_home)  # the workers' working and local directory
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None,
                                  local_directory=str(worker_home)) as cluster, \
            distributed.Client(cluster) as client:
        # the sweep directory is made after the workers started, relative to the driver's
        # working directory, and the workers are refused any access below driver_home
        monkeypatch.chdir(driver_home)
        client.run(_forbid, str(driver_home))
        sweep = Path("sweep")
        first = run_sweep(spec, sweep, scheduler=cluster.scheduler_address,
                          fail_points={k15})
        # resumed on the cluster: 12 m/min is kept, 15 m/min starts from its gait file,
        # whose text the driver sends
        second = run_sweep(spec, sweep, scheduler=cluster.scheduler_address)
        views = client.run(_worker_view, str(sweep), str(driver_home / sweep))
        touched = client.run(_touched)
    for view in views.values():
        assert view == {"cwd": str(worker_home), "relative_exists": False, "refused": True}
    assert all(not paths for paths in touched.values()), touched
    assert os.getpid() not in {int(o.worker.rsplit(":", 1)[1]) for o in
                               first.outcomes + second.outcomes}
    assert (first.counts.succeeded, first.counts.failed) == (1, 1)
    assert (second.counts.kept, second.counts.succeeded, second.counts.failed) == (1, 1, 0)
    assert {o.key: o.warm for o in second.outcomes} == {k15: "file"}
    rows = read_summary(driver_home / sweep / SUMMARY_FILE)
    assert [r.file for r in rows] == [k12, k15] and all(r.success for r in rows)
    for row in rows:  # every gait file is whole and is the row's solve
        gait = Gait.load(driver_home / sweep / row.file)
        assert gait.success and gait.cost_value == row.cost
        assert gait.speed == pytest.approx(row.speed_m_s)
    assert not list((driver_home / sweep).rglob("*.tmp"))
    assert not list(worker_home.rglob("*.gait.json"))
