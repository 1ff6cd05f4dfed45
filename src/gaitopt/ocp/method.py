"""The interface of a transcription method (Hermite-Simpson, trapezoidal).

Every function works on CasADi matrices and on numpy arrays alike. Arguments are given
column-wise per interval: ``x_k, x_k1, f_k, f_k1`` are (n, N) (states and dynamics at the left
and right knot of each interval), ``h`` has the same shape (interval length repeated),
``u_k, u_k1`` are (m, N). Numeric interpolation uses ``s in [0, 1]``, the position within an
interval as a fraction of h.
"""

from __future__ import annotations

from typing import Any, Protocol


class Method(Protocol):
    """A collocation scheme over knots with piecewise-linear controls."""

    name: str
    order: int
    """Order of the state error on mesh refinement (h^order)."""
    needs_midpoint_dynamics: bool
    """Whether the defects use the dynamics at the interval midpoints."""
    midpoint_variables: bool
    """Whether the midpoint states are decision variables (separated form): then the NLP has
    the midpoint defects ``x_m - midpoint_state(...) = 0`` and the dynamics, path constraints
    and integrand at a midpoint are evaluated at the variable ``x_m``, never composed with the
    knot dynamics."""

    def midpoint_state(self, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """State at the interval midpoint from the scheme's interpolant, (n, N)."""

    def defects(self, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, f_m: Any, h: Any) -> Any:
        """The collocation defects (zero when the dynamics hold), (n, N)."""

    def quadrature(self, l_k: Any, l_k1: Any, l_m: Any, h: Any) -> Any:
        """Integral over each interval of a function given at knots and midpoints, (1, N)."""

    def state_at(self, s: Any, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """State interpolant at fraction s of each interval."""

    def rate_at(self, s: Any, x_k: Any, x_k1: Any, f_k: Any, f_k1: Any, h: Any) -> Any:
        """Time derivative of the state interpolant at fraction s of each interval."""


def midpoint_control(u_k: Any, u_k1: Any) -> Any:
    """Control at an interval midpoint: the average of the knot controls (piecewise linear)."""
    return 0.5 * (u_k + u_k1)


def control_at(s: Any, u_k: Any, u_k1: Any) -> Any:
    """Piecewise-linear control at fraction s of each interval."""
    return u_k + s * (u_k1 - u_k)
