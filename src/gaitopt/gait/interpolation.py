"""Values of a stored gait phase between its knots, by the interpolation rules the gait file
names (``GaitPhase.interpolation``): the states by the transcription's cubic Hermite
interpolant of the knot states and rates, controls and contact forces piecewise linear.

Times ``t`` are in s on the gait's clock, shapes ``(M,)``; results ``(M, n)`` (states),
``(M, nu)`` (controls, N m) or ``{contact: (M, 2)}`` (forces, N).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from gaitopt.gait.gait_file import GaitPhase

Array = NDArray[np.float64]


def cubic_hermite(s: Array, x_k: Array, x_k1: Array, f_k: Array, f_k1: Array,
                  h: Array) -> Array:
    """The cubic Hermite interpolant at the fraction ``s`` of a segment of length ``h`` from
    its end values ``x_k``, ``x_k1`` and rates ``f_k``, ``f_k1``: the gait file's
    ``cubic_hermite`` rule. The same arithmetic, in the same order, as the transcription's
    :meth:`gaitopt.ocp.hermite_simpson.HermiteSimpson.state_at` (tests check they agree
    exactly), on NumPy arrays: reading a gait file loads no CasADi."""
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * x_k + h10 * h * f_k + h01 * x_k1 + h11 * h * f_k1


def phase_states_at(phase: GaitPhase, t: Array) -> Array:
    """Phase states (M, n) at times ``t`` (M,) by cubic Hermite interpolation of the knots:
    the transcription's own interpolant (:func:`cubic_hermite`, with s = (t - t_k)/h on the
    segment [t_k, t_k+1] of length h)."""
    if phase.interpolation["states"] != "cubic_hermite":
        raise ValueError(f"unsupported state interpolation {phase.interpolation['states']!r}")
    t = np.atleast_1d(np.asarray(t, dtype=float))
    k = np.clip(np.searchsorted(phase.t, t, side="right") - 1, 0, phase.t.size - 2)
    h = (phase.t[k + 1] - phase.t[k])[:, None]
    s = ((t - phase.t[k]) / h[:, 0])[:, None]
    return np.asarray(cubic_hermite(s, phase.x[k], phase.x[k + 1], phase.xdot[k],
                                    phase.xdot[k + 1], h), dtype=float)


def phase_controls_at(phase: GaitPhase, t: Array) -> Array:
    """Controls (M, nu) at times ``t`` (M,), piecewise linear between knots."""
    if phase.interpolation["controls"] != "piecewise_linear":
        raise ValueError(f"unsupported control interpolation "
                         f"{phase.interpolation['controls']!r}")
    t = np.atleast_1d(np.asarray(t, dtype=float))
    return np.stack([np.interp(t, phase.t, phase.u[:, j]) for j in range(phase.u.shape[1])],
                    axis=1)


def phase_forces_at(phase: GaitPhase, t: Array) -> dict[str, Array]:
    """Contact forces (M, 2) N at times ``t`` (M,), piecewise linear between knots."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    return {c: np.stack([np.interp(t, phase.t, f[:, 0]), np.interp(t, phase.t, f[:, 1])],
                        axis=1) for c, f in phase.contact_forces.items()}
