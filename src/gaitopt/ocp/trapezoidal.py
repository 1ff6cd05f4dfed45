"""Trapezoidal collocation.

Variables live at the knots. On interval k of length h the defect is
``x_{k+1} - x_k - h (f_k + f_{k+1}) / 2 = 0``, the control is linear, and the state
interpolant is the quadratic whose slope is linear from f_k to f_{k+1}:
``x(t_k + s h) = x_k + s h f_k + s^2 h (f_{k+1} - f_k) / 2``. Its midpoint value is
``(x_k + x_{k+1}) / 2 + h (f_k - f_{k+1}) / 8`` (same formula as Hermite-Simpson), used for
path constraints imposed at midpoints. Integrals use the trapezoidal rule. The state error is
O(h^2).
"""

from __future__ import annotations

from typing import Any


class Trapezoidal:
    """The trapezoidal scheme (see the module docstring)."""

    name = "trapezoidal"
    order = 2
    needs_midpoint_dynamics = False
    midpoint_variables = False

    def midpoint_state(self, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """``(x_k + x_{k+1}) / 2 + h (f_k - f_{k+1}) / 8`` (the quadratic at s = 1/2)."""
        return 0.5 * (x_k + x_k1) + h * (f_k - f_k1) / 8.0

    def defects(self, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, f_m: Any, h: Any) -> Any:
        """``x_{k+1} - x_k - h (f_k + f_{k+1}) / 2`` (f_m is unused)."""
        return x_k1 - x_k - h * (f_k + f_k1) / 2.0

    def quadrature(self, l_k: Any, l_k1: Any, l_m: Any, h: Any) -> Any:
        """Trapezoidal rule ``h (L_k + L_{k+1}) / 2`` (l_m is unused)."""
        return h * (l_k + l_k1) / 2.0

    def state_at(self, s: Any, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """Quadratic interpolant at fraction s."""
        return x_k + s * h * f_k + s**2 * h * (f_k1 - f_k) / 2.0

    def rate_at(self, s: Any, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """Linear slope ``f_k + s (f_{k+1} - f_k)``."""
        return f_k + s * (f_k1 - f_k)
