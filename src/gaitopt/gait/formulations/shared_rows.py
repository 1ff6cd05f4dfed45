"""Constraint rows that both formulations state alike: the friction cone of a force or an
impulse, the swing clearance profile, and the scale of the rows that are lengths."""

from __future__ import annotations

from typing import Any

#: Scale (m) of the constraints that are lengths (tip heights, landing positions) on the
#: reference biped (1 m legs); ``l / l_ref`` times it on another model.
LENGTH_SCALE = 0.1


def friction_rows(friction: float | None, tangential: Any, normal: Any) -> list[Any]:
    """``[mu n - t, mu n + t]`` (each ``>= 0``: the force or impulse ``(t, n)`` within the
    friction cone of coefficient ``mu``), or none without friction."""
    if friction is None:
        return []
    return [friction * normal - tangential, friction * normal + tangential]


def clearance_profile(clearance: float, s: Any, profile: str) -> Any:
    """The least swing-tip height (m) at normalised single-support time ``s`` in [0, 1]:
    ``c 4 s (1 - s)`` (``"parabola"``) or ``c (4 s (1 - s))^2`` (``"quartic"``); both are 0
    at the liftoff and the heel strike and ``c`` at mid-swing. The parabola's slope at the
    ends, ``4 c / T1``, is a least vertical tip velocity at both events; the quartic's is
    zero."""
    bump = 4.0 * s * (1.0 - s)
    return clearance * (bump if profile == "parabola" else bump * bump)
