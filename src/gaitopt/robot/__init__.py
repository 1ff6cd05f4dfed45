"""Robot models: immutable descriptions of planar kinematic trees and their model files."""

from gaitopt.robot.errors import ModelError
from gaitopt.robot.loader import (
    builtin_names,
    builtin_text,
    load_model,
    model_from_yaml,
    model_to_yaml,
)
from gaitopt.robot.model import Actuator, Contact, Joint, Link, RobotModel, Shape, model_to_dict
from gaitopt.robot.schema import model_from_dict

__all__ = [
    "Actuator", "Contact", "Joint", "Link", "ModelError", "RobotModel", "Shape",
    "builtin_names", "builtin_text", "load_model", "model_from_dict", "model_from_yaml",
    "model_to_dict", "model_to_yaml",
]
