"""A different biped from a model file: other masses, lengths, inertias, centres of mass off
the link centres and tighter torque bounds, written as YAML and loaded; it solves, the torque
bounds hold (and bind), and the gait is physically right (Pinocchio) and verifies."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.robot import RobotModel, load_model
from gaitopt.robot.loader import builtin_text
from tests.gait.conftest import (
    Reference,
    SolveFn,
    assert_physics,
    lowest_sample_normal_force,
    recomputed_cost,
)

RefFn = Callable[..., Reference]

THIGH, SHANK = 0.45, 0.48  # lengths (m)
#: Hip and knee torque bound (N m); the ankles get half. Tight enough to bind.
BOUND = 9.0
LINKS: dict[str, dict[str, Any]] = {
    "torso": {"mass": 24.0, "length": 0.6, "com": [0.25, 0.0], "inertia": 0.5},
    "thigh": {"mass": 6.0, "length": THIGH, "com": [0.18, 0.0], "inertia": 0.08},
    "shank": {"mass": 3.5, "length": SHANK, "com": [0.2, 0.0], "inertia": 0.05},
}


def write_model(folder: Path) -> Path:
    data = yaml.safe_load(builtin_text("five-link"))
    data["name"] = "test-biped"
    data["description"] = "A five-link biped unlike the paper's, for the tests."
    for link in data["links"]:
        link.pop("shape")
        link.update(LINKS[link["name"].split("_")[0]])
        if link["name"].startswith("shank"):
            link["joint"]["at"] = [THIGH, 0.0]
    for contact in data["contacts"]:
        contact["at"] = [SHANK, 0.0]
    for act in data["actuators"]:
        bound = BOUND / 2 if act.get("contact") else BOUND
        act["limits"] = [-bound, bound]
    path = folder / "test-biped.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def model(tmp_path_factory: pytest.TempPathFactory) -> RobotModel:
    return load_model(write_model(tmp_path_factory.mktemp("model")))


@pytest.fixture(scope="module")
def gait(model: RobotModel, solved: SolveFn) -> Gait:
    return solved(GaitOptions.paper(), model).gait


def test_the_model_file_is_what_was_written(model: RobotModel) -> None:
    assert model.name == "test-biped"
    assert model.total_mass == pytest.approx(24.0 + 2 * (6.0 + 3.5))
    thigh = model.link("thigh_1")
    assert (thigh.mass, thigh.length, thigh.com, thigh.inertia) == (6.0, THIGH, (0.18, 0.0),
                                                                    0.08)
    assert model.actuators[model.actuator_index("ankle_2")].limits == (-BOUND / 2, BOUND / 2)


def test_other_model_solves_within_its_torque_bounds(model: RobotModel, gait: Gait) -> None:
    assert gait.success and gait.solver["max_violation"] < 1e-6
    assert gait.model.content_hash() == model.content_hash()  # the file embeds the model
    u = np.vstack([ph.u for ph in gait.phases])
    bounds = np.array([a.limits[1] for a in model.actuators])
    use = np.max(np.abs(u), axis=0) / bounds
    assert np.all(use <= 1.0 + 1e-6), use
    assert np.max(use) > 0.999  # the tighter bounds are active: they shaped the gait
    assert 0.03 < gait.step_length < 0.3


def test_other_model_gait_is_physically_right(model: RobotModel, gait: Gait,
                                              reference: RefFn) -> None:
    """Pinocchio, built from this model (centres of mass off the link centres included),
    agrees with the saved knots; the dense samples' normal forces are non-negative."""
    ref = reference(model)
    assert_physics(ref, gait)
    assert lowest_sample_normal_force(ref, gait) >= -1e-3
    assert recomputed_cost(gait) == pytest.approx(gait.cost_value, rel=1e-9)


def test_other_model_gait_verifies(gait: Gait) -> None:
    """Every check of ``verify`` passes."""
    report = verify_gait(gait)
    assert report.passed, [(c.name, c.value) for c in report.checks if not c.passed]
