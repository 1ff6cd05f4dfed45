"""gaitopt: energy-optimal walking gaits for planar multibody bipeds.

The front door: everything a user needs to solve, inspect, verify and save a gait.

>>> from gaitopt import GaitOptions, load_model
>>> model = load_model("five-link")
>>> model.coordinate_names
('x', 'y', 'torso', 'hip_1', 'knee_1', 'hip_2', 'knee_2')
>>> GaitOptions(speed=0.2).variant
'ankle+impulse'

The names are imported on first use (``import gaitopt`` stays fast: CasADi and SciPy load only
when a solver or ``verify_gait`` is needed).
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING, Any, cast

from gaitopt import views as _views

__version__ = "0.1.0"

#: Public name -> the module that defines it.
_EXPORTS: dict[str, str] = {
    "solve_gait": "gaitopt.gait.api",
    "GaitOptions": "gaitopt.gait.options",
    "GaitOptionsError": "gaitopt.gait.options",
    "Gait": "gaitopt.gait.gait_file",
    "GaitFileError": "gaitopt.gait.gait_file",
    "verify_gait": "gaitopt.analysis.verify",
    "VerifyReport": "gaitopt.analysis.verify",
    "load_model": "gaitopt.robot",
    "RobotModel": "gaitopt.robot",
    "ModelError": "gaitopt.robot",
    "gait_stability": "gaitopt.analysis.stability",
    "StabilityReport": "gaitopt.analysis.stability",
}

__all__ = ["Gait", "GaitFileError", "GaitOptions", "GaitOptionsError", "ModelError",
           "RobotModel", "StabilityReport", "VerifyReport", "__version__", "gait_stability",
           "load_model", "solve_gait", "verify_gait"]

if TYPE_CHECKING:
    from gaitopt.analysis.stability import StabilityReport, gait_stability
    from gaitopt.analysis.verify import VerifyReport, verify_gait
    from gaitopt.gait.api import solve_gait
    from gaitopt.gait.gait_file import Gait, GaitFileError
    from gaitopt.gait.options import GaitOptions, GaitOptionsError
    from gaitopt.robot import ModelError, RobotModel, load_model


def _notebook_views() -> _views.GaitViews:
    """:mod:`gaitopt.viz.notebook`, imported on a gait's first view (:mod:`gaitopt.views`)."""
    module: ModuleType = importlib.import_module("gaitopt.viz.notebook")
    return cast(_views.GaitViews, module)


_views.install_gait_views(_notebook_views)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'gaitopt' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
