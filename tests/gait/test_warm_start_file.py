"""A warm start from a saved gait restarts IPOPT from the NLP point and multipliers the file
keeps (solver.warm_start), in a few iterations, to the same optimum as a cold solve."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from gaitopt.gait.api import restart_point, solve_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.robot import load_model
from tests.gait.conftest import Solved

SolveFn = Callable[..., Solved]


def test_warm_start_from_a_file_restarts_with_its_multipliers(
        solved: SolveFn, default_gait_file: Path) -> None:
    gait = Gait.load(default_gait_file)
    assert set(gait.solver["warm_start"]) == {"w", "lam_x", "lam_g", "layout", "method"}
    faster = GaitOptions.paper(speed=0.21)
    warm = solve_gait("five-link", faster, warm_start=gait)
    cold = solved(faster).gait
    first = warm.solver["stages"][0]
    assert first["name"] == "warm start" and first["success"]
    assert first["iterations"] <= 20  # 41 from the trajectories alone (measured)
    assert warm.cost_value == pytest.approx(cold.cost_value, rel=1e-5)


def test_the_restart_point_is_used_only_where_it_fits(default_gait_file: Path) -> None:
    gait = Gait.load(default_gait_file)
    model = load_model("five-link")
    assert restart_point(model, GaitOptions.paper(speed=0.21), gait) is not None
    assert restart_point(model, GaitOptions.paper(knots=(10, 5)), gait) is None  # another grid
    data = gait.to_dict()
    del data["solver"]["warm_start"]  # a file written before it existed
    assert restart_point(model, GaitOptions.paper(), Gait.from_dict(data)) is None
