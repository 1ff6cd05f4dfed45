"""The same sweep on a Dask cluster (a LocalCluster of two single-threaded processes)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from gaitopt.gait.gait_file import Gait
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
