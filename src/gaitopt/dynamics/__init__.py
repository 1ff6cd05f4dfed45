"""Planar rigid-body dynamics of a floating-base tree (paper section 3, appendix 1).

Every function takes NumPy/list numbers or CasADi SX/MX symbols and returns the same kind
(``np.ndarray`` or CasADi). Conventions: :mod:`gaitopt.robot.model` and ``docs/dynamics.md``.
"""

from gaitopt.dynamics.aba import aba, inverse_mass_times
from gaitopt.dynamics.actuation import actuation_matrix, generalized_forces
from gaitopt.dynamics.backend import SingularSystemError
from gaitopt.dynamics.contact import ContactSolution, contact_dynamics
from gaitopt.dynamics.crba import crba
from gaitopt.dynamics.energy import (
    angular_momentum,
    center_of_mass,
    kinetic_energy,
    linear_momentum,
    potential_energy,
    total_energy,
)
from gaitopt.dynamics.impact import (
    ImpactSolution,
    LiftoffSolution,
    hip_link,
    impact,
    liftoff_impulse,
)
from gaitopt.dynamics.kinematics import (
    LinkFrame,
    contact_acceleration,
    contact_jacobian,
    contact_position,
    contact_velocity,
    link_angles,
    link_frames,
    point_acceleration,
    point_jacobian,
    point_position,
    point_velocity,
)
from gaitopt.dynamics.rnea import bias_forces, gravity_forces, rnea

__all__ = [
    "ContactSolution", "ImpactSolution", "LiftoffSolution", "LinkFrame", "SingularSystemError",
    "aba", "actuation_matrix", "angular_momentum", "bias_forces", "center_of_mass",
    "contact_acceleration", "contact_dynamics", "contact_jacobian", "contact_position",
    "contact_velocity", "crba", "generalized_forces", "gravity_forces", "hip_link", "impact",
    "inverse_mass_times", "kinetic_energy", "liftoff_impulse", "linear_momentum",
    "link_angles", "link_frames", "point_acceleration", "point_jacobian", "point_position",
    "point_velocity", "potential_energy", "rnea", "total_energy",
]
