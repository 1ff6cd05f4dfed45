"""The size of a model, and the reference biped every tuned constant was tuned on.

The defaults, bounds, guesses and NLP scales of the walking problem were tuned on the
paper's five-link biped: legs of ``l_ref = 1 m`` (hip to ground, standing), ``m_ref = 42 kg``,
``g_ref = 9.81 m/s^2``. For another model each such constant is the reference value carried
over at equal dimensionless value, with the model's characteristic leg length ``l``
(:func:`leg_length`), mass ``m`` (total) and gravity ``g`` (Froude scaling; units as in
``docs/conventions.md``):

=============  ===========================  ==============================================
quantity       unit                         factor from the reference biped's value
=============  ===========================  ==============================================
length         m                            ``l / l_ref``
speed          m/s                          ``sqrt(g l / (g_ref l_ref))`` (same Froude
                                            number ``v^2 / (g l)``)
time           s                            ``sqrt((l / g) / (l_ref / g_ref))``
rate           rad/s                        ``1 / time factor``
force          N                            ``m g / (m_ref g_ref)``
impulse        N s                          force factor x time factor
torque         N m                          force factor x length factor
power          W                            force factor x speed factor
paper cost     N^2 m s (torque^2 time / L)  torque factor^2 x time factor / length factor
=============  ===========================  ==============================================

For the five-link biped (and any model of the same ``l``, ``m`` and ``g``) every factor is
exactly 1.0 (numerator and denominator are the same floating-point product), so its
constants keep their values to the last bit: the converged, documented five-link results do
not move. A model that is the five-link biped with every length times ``a`` and every mass
times ``b`` (torque bounds times ``b a``) has the same optimum in dimensionless units.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from gaitopt.dynamics.kinematics import contact_position, point_position
from gaitopt.robot.model import RobotModel

#: The reference biped's characteristic leg length (m): the five-link biped's hip height
#: standing (thigh 0.5 m + shank 0.5 m).
REFERENCE_LEG_LENGTH = 1.0
#: The reference biped's mass (kg): the five-link biped's 42 kg (paper, Table 1).
REFERENCE_MASS = 42.0
#: The reference biped's gravity (m/s^2).
REFERENCE_GRAVITY = 9.81


@dataclass(frozen=True)
class ModelScale:
    """A model's characteristic leg length ``leg_length`` (m), ``mass`` (kg) and
    ``gravity`` (m/s^2), and the factors (module docstring) that carry a reference
    biped's value of each unit over to it."""

    leg_length: float
    mass: float
    gravity: float

    @property
    def length_factor(self) -> float:
        """``l / l_ref``."""
        return self.leg_length / REFERENCE_LEG_LENGTH

    @property
    def speed_factor(self) -> float:
        """``sqrt(g l / (g_ref l_ref))``."""
        return math.sqrt((self.gravity * self.leg_length)
                         / (REFERENCE_GRAVITY * REFERENCE_LEG_LENGTH))

    @property
    def time_factor(self) -> float:
        """``sqrt((l / g) / (l_ref / g_ref))``."""
        return math.sqrt((self.leg_length / self.gravity)
                         / (REFERENCE_LEG_LENGTH / REFERENCE_GRAVITY))

    @property
    def force_factor(self) -> float:
        """``m g / (m_ref g_ref)``."""
        return (self.mass * self.gravity) / (REFERENCE_MASS * REFERENCE_GRAVITY)

    def length(self, reference: float) -> float:
        """A length (m) of the reference biped carried over to this model."""
        return reference * self.length_factor

    def speed(self, reference: float) -> float:
        """A speed (m/s) of the reference biped at the same Froude number."""
        return reference * self.speed_factor

    def to_reference_speed(self, speed: float) -> float:
        """This model's speed (m/s) as the reference biped's speed of equal Froude number."""
        return speed / self.speed_factor

    def rate(self, reference: float) -> float:
        """An angular rate (rad/s) of the reference biped (1 / time)."""
        return reference / self.time_factor

    def force(self, reference: float) -> float:
        """A force (N) of the reference biped (times ``m g / (m_ref g_ref)``)."""
        return reference * self.force_factor

    def impulse(self, reference: float) -> float:
        """An impulse (N s) of the reference biped (force x time)."""
        return reference * (self.force_factor * self.time_factor)

    def power(self, reference: float) -> float:
        """A power (W) of the reference biped (force x speed)."""
        return reference * (self.force_factor * self.speed_factor)

    def paper_cost(self, reference: float) -> float:
        """A value of the paper's cost (N^2 m s: torque^2 x time / length) of the reference
        biped."""
        torque = self.force_factor * self.length_factor
        return reference * (torque * torque * self.time_factor / self.length_factor)


#: The reference biped's scale (every factor 1).
REFERENCE = ModelScale(REFERENCE_LEG_LENGTH, REFERENCE_MASS, REFERENCE_GRAVITY)


def leg_length(model: RobotModel) -> float:
    """The characteristic leg length ``l`` (m): the height of the hip (the joint of the
    first link of the chain from the base to the first contact point) above the lowest
    contact point, standing (every coordinate 0: legs straight down). 1.0 m for the
    five-link biped, 0.9275 m for ``seven-link`` and ``adult-point-feet``.

    Raises:
        ValueError: the model has no contact point, or no contact point below the hip.
    """

    if not model.contacts:
        raise ValueError(f"model {model.name!r} has no contact point: no leg length")
    zero = [0.0] * model.nq
    chain = model.chain(model.link_index(model.contacts[0].link))
    parent, hip = 0, (0.0, 0.0)  # a contact on the base: its origin
    if len(chain) > 1:
        root = model.links[chain[1]]
        parent = model.parent_index(chain[1])
        hip = root.joint.at if root.joint is not None else hip
    y_hip = float(point_position(model, zero, parent, hip)[1])
    lowest = min(float(contact_position(model, zero, c.name)[1]) for c in model.contacts)
    length = y_hip - lowest
    if not length > 0.0:
        raise ValueError(f"model {model.name!r}: standing, no contact point is below the hip "
                         f"(hip at y = {y_hip:.3g} m, lowest point at {lowest:.3g} m)")
    return length


@functools.lru_cache(maxsize=32)
def model_scale(model: RobotModel) -> ModelScale:
    """The :class:`ModelScale` of ``model``: :func:`leg_length`, the total mass and the
    magnitude of its gravity vector."""
    return ModelScale(leg_length(model), model.total_mass, math.hypot(*model.gravity))
