"""Fixtures for the dynamics tests: the five-link model and random planar trees."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from dynamics_helpers import random_tree  # noqa: E402

from gaitopt.robot import RobotModel, load_model  # noqa: E402


@pytest.fixture(scope="session")
def five_link() -> RobotModel:
    return load_model("five-link")


@pytest.fixture(scope="session", params=["five-link", "random-3", "random-11"])
def model(request: pytest.FixtureRequest) -> RobotModel:
    """The five-link biped and two random trees (7 and 5+ links)."""
    if request.param == "five-link":
        return load_model("five-link")
    seed = int(request.param.split("-")[1])
    return random_tree(seed, n_links=7 if seed == 3 else None)
