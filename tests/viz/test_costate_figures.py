"""The gait file's optional costates: round trip, older files, shape checks, the figure."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from gaitopt.gait.record.file import Gait
from gaitopt.viz.costate_figures import costates_figure
from tests.viz.synthetic import synthetic_gait


def with_costates(gait: Gait) -> Gait:
    """``gait`` with made-up costates (K, n): lambda_j(t) = (j + 1) cos(t)."""
    phases = tuple(dataclasses.replace(
        ph, costates=np.cos(ph.t)[:, None] * np.arange(1.0, len(ph.state_names) + 1))
        for ph in gait.phases)
    return dataclasses.replace(gait, phases=phases)


def test_costates_round_trip_through_the_file(tmp_path: Path) -> None:
    gait = with_costates(synthetic_gait())
    back = Gait.load(gait.save(tmp_path / "g.gait.json"))
    for a, b in zip(gait.phases, back.phases, strict=True):
        assert b.costates is not None and a.costates is not None
        np.testing.assert_array_equal(b.costates, a.costates)
        assert b.costates.shape == (a.t.size, len(a.state_names))


def test_a_file_without_costates_loads(tmp_path: Path) -> None:
    path = synthetic_gait().save(tmp_path / "old.gait.json")
    assert all("costates" not in ph for ph in json.loads(path.read_text())["phases"])
    assert all(ph.costates is None for ph in Gait.load(path).phases)


def test_costates_of_the_wrong_shape_are_refused() -> None:
    data = with_costates(synthetic_gait()).to_dict()
    data["phases"][1]["costates"] = data["phases"][1]["costates"][:-1]
    with pytest.raises(ValueError, match=r"phases\[1\]\.costates: expected shape"):
        Gait.from_dict(data)


def test_the_figure_draws_every_state_of_every_phase() -> None:
    gait = with_costates(synthetic_gait())
    fig = costates_figure(gait)
    assert isinstance(fig, Figure)
    for ph in gait.phases:
        (ax,) = [a for a in fig.axes if a.get_gid() == f"costates:{ph.name}"]
        lines = {line.get_label(): line for line in ax.get_lines()}
        assert set(ph.state_names) <= set(lines)
        name = ph.state_names[-1]
        assert ph.costates is not None
        np.testing.assert_allclose(lines[name].get_ydata(), ph.costates[:, -1])
    assert isinstance(gait.plot("costates"), Figure)


def test_the_figure_needs_costates() -> None:
    with pytest.raises(ValueError, match="no costates"):
        costates_figure(synthetic_gait())
