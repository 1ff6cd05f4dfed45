"""Robot models: immutable descriptions of planar kinematic trees and their model files."""

from gaitopt.robot.loader import (
    ModelError,
    builtin_names,
    load_model,
    model_from_dict,
    model_from_yaml,
    model_to_dict,
    model_to_yaml,
)
from gaitopt.robot.model import Actuator, Contact, Joint, Link, RobotModel

__all__ = [
    "Actuator", "Contact", "Joint", "Link", "ModelError", "RobotModel", "builtin_names",
    "load_model", "model_from_dict", "model_from_yaml", "model_to_dict", "model_to_yaml",
]
