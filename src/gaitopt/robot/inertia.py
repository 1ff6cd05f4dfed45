"""The inertia of a link from its shape: a uniform ellipsoid or a thin rod (kg m^2, about the
link's centre of mass, about the axis normal to the plane)."""

from __future__ import annotations

from gaitopt.robot.model import Shape

#: Relative tolerance when a link gives both ``inertia`` and ``shape``.
INERTIA_RTOL = 1e-9


def ellipsoid_inertia(mass: float, length: float, radius: float) -> float:
    """Inertia (kg m^2) about the axis through the centre normal to the plane of a uniform
    ellipsoid with semi-axes ``a = length/2`` (along the link), ``b = c = radius``:
    ``I = m (a^2 + b^2) / 5``."""
    a = length / 2.0
    return mass * (a * a + radius * radius) / 5.0  # products give inf, never OverflowError


def rod_inertia(mass: float, length: float) -> float:
    """Inertia (kg m^2) of a thin uniform rod about its centre: ``I = m length^2 / 12``."""
    return mass * (length * length) / 12.0


def shape_inertia(shape: Shape, mass: float, length: float) -> float:
    """Inertia (kg m^2) about the centre of a link of ``mass`` kg and ``length`` m."""
    if shape.type == "ellipsoid":
        assert shape.radius is not None
        return ellipsoid_inertia(mass, length, shape.radius)
    return rod_inertia(mass, length)
