"""Hermite-Simpson collocation in DIRCOL's compressed form.

Variables live at the knots only. On interval k of length h, with f_k = f(x_k, u_k, p, t_k):

* the state is the cubic Hermite interpolant through (x_k, f_k) and (x_{k+1}, f_{k+1});
  its midpoint value is ``x_m = (x_k + x_{k+1}) / 2 + h (f_k - f_{k+1}) / 8``;
* the control is linear: ``u_m = (u_k + u_{k+1}) / 2``;
* the Simpson defect ``x_{k+1} - x_k - h (f_k + 4 f_m + f_{k+1}) / 6 = 0`` with
  ``f_m = f(x_m, u_m, p, t_k + h/2)`` makes the cubic's slope match f at the midpoint too;
* integrals use Simpson's rule ``h (L_k + 4 L_m + L_{k+1}) / 6``.

The state error is O(h^4) at the knots for smooth problems.
"""

from __future__ import annotations

from typing import Any


class HermiteSimpson:
    """The compressed Hermite-Simpson scheme (see the module docstring)."""

    name = "hermite-simpson"
    order = 4
    needs_midpoint_dynamics = True
    midpoint_variables = False

    def midpoint_state(self, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """``(x_k + x_{k+1}) / 2 + h (f_k - f_{k+1}) / 8``."""
        return 0.5 * (x_k + x_k1) + h * (f_k - f_k1) / 8.0

    def defects(self, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, f_m: Any, h: Any) -> Any:
        """``x_{k+1} - x_k - h (f_k + 4 f_m + f_{k+1}) / 6``."""
        return x_k1 - x_k - h * (f_k + 4.0 * f_m + f_k1) / 6.0

    def quadrature(self, l_k: Any, l_k1: Any, l_m: Any, h: Any) -> Any:
        """Simpson's rule ``h (L_k + 4 L_m + L_{k+1}) / 6``."""
        return h * (l_k + 4.0 * l_m + l_k1) / 6.0

    def state_at(self, s: Any, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """Cubic Hermite interpolant at fraction s."""
        h00 = 2 * s**3 - 3 * s**2 + 1
        h10 = s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        h11 = s**3 - s**2
        return h00 * x_k + h10 * h * f_k + h01 * x_k1 + h11 * h * f_k1

    def rate_at(self, s: Any, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """Time derivative of the cubic Hermite interpolant at fraction s."""
        d00 = 6 * s**2 - 6 * s
        d10 = 3 * s**2 - 4 * s + 1
        d01 = -6 * s**2 + 6 * s
        d11 = 3 * s**2 - 2 * s
        return (d00 * x_k + d01 * x_k1) / h + d10 * f_k + d11 * f_k1
