"""Fixtures shared by the study tests: the built-in models, loaded once per module."""

from __future__ import annotations

import pytest

from gaitopt.robot import RobotModel, load_model


@pytest.fixture(scope="module")
def five_link() -> RobotModel:
    return load_model("five-link")


@pytest.fixture(scope="module")
def seven_link() -> RobotModel:
    return load_model("seven-link")
