"""Units at the user's edge: SI inside, speeds with a unit on the command line.

The paper quotes speeds in m/min; the CLI accepts ``12m/min``, ``0.2m/s``, ``0.72km/h`` or a
bare number (m/s), and prints both m/s and m/min.
"""

from __future__ import annotations

import math
import re

#: Metres per second of one unit.
SPEED_UNITS: dict[str, float] = {"m/s": 1.0, "m/min": 1.0 / 60.0, "km/h": 1000.0 / 3600.0}

_SPEED = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-z/]*)\s*$")


def parse_speed(text: str) -> float:
    """A speed in m/s from text such as ``12m/min``, ``0.2 m/s``, ``0.72km/h`` or ``0.2``.

    Raises ``ValueError`` naming the accepted forms when the text is not a speed.
    """
    match = _SPEED.match(text)
    if not match:
        raise ValueError(f"speed {text!r} is not a number with an optional unit "
                         f"({', '.join(SPEED_UNITS)}), e.g. 12m/min")
    value, unit = float(match.group(1)), match.group(2) or "m/s"
    if unit not in SPEED_UNITS:
        raise ValueError(f"speed {text!r} has unknown unit {unit!r}; use one of "
                         f"{', '.join(SPEED_UNITS)}")
    if not math.isfinite(value):
        raise ValueError(f"speed {text!r} is not finite")
    return value * SPEED_UNITS[unit]


def m_per_min(speed_m_s: float) -> float:
    """Convert m/s to m/min."""
    return speed_m_s * 60.0


def format_speed(speed_m_s: float) -> str:
    """``0.2000 m/s (12.00 m/min)``."""
    return f"{speed_m_s:.4f} m/s ({m_per_min(speed_m_s):.2f} m/min)"
