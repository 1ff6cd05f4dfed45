"""Hermite-Simpson collocation in the separated form: midpoint states are NLP variables.

Same discretization as the compressed form (:mod:`gaitopt.ocp.hermite_simpson`): cubic
Hermite states through (x_k, f_k) and (x_{k+1}, f_{k+1}), piecewise-linear controls, Simpson
quadrature. The difference is how the NLP states it. The midpoint state ``x_m`` of every
interval is a decision variable, and each interval has two constraint blocks (n rows each)::

    x_m - (x_k + x_{k+1}) / 2 - h (f_k - f_{k+1}) / 8 = 0       (midpoint defect)
    x_{k+1} - x_k - h (f_k + 4 f_m + f_{k+1}) / 6 = 0            (Simpson defect)

with ``f_k = f(x_k, u_k, p, t_k)`` and ``f_m = f(x_m, u_m, p, t_k + h/2)``, where the midpoint
control is tied to the linear interpolant ``u_m = (u_k + u_{k+1}) / 2`` (no variable). Every
constraint row touches one dynamics evaluation per grid point, never ``f`` of an expression
containing ``f``: the exact Hessian of the Lagrangian is a sum of one small block per knot and
per midpoint instead of the dense composition of the compressed form.

The midpoint states take the path state bounds by default (``transcribe(...,
midpoint_bounds=True)``), so the states respect them between knots too. Without those bounds,
eliminating ``x_m`` with the midpoint defect gives back the compressed NLP, and both forms have
the same optimum on every mesh (the same objective, the same knot values); with them, the
optima differ only where a state bound would be violated between knots, by an amount that
vanishes as the mesh is refined. The NLP has n N more variables and equality constraints.
"""

from __future__ import annotations

from gaitopt.ocp.hermite_simpson import HermiteSimpson


class HermiteSimpsonSeparated(HermiteSimpson):
    """The separated Hermite-Simpson scheme (see the module docstring).

    ``midpoint_state`` is the value the midpoint defect ties ``x_m`` to (the NLP assembly
    adds ``x_m - midpoint_state(...)``); the defects, quadrature and interpolants are those of
    the compressed form.
    """

    name = "hermite-simpson-separated"
    midpoint_variables = True

