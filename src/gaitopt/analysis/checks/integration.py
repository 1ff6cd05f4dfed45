"""Re-integration of the saved motion under the saved controls.

From every knot ``(q_k, qd_k)`` of a phase, ``qdd = contact_dynamics(q, qd, u(t))`` with the
phase's contacts held (:func:`gaitopt.dynamics.functions.contact_dynamics_function`) is
integrated over the interval ``[t_k, t_k+1]`` by SciPy's DOP853 (rtol = atol = 1e-10) under
the controls interpolated as the file says (piecewise linear, so one interval at a time: the
integrator never steps over a kink of the controls), and compared with the next knot.

``integration.interval`` compares the error with the grid's own error estimate (the file's
optional ``error_estimate`` of each phase, :mod:`gaitopt.ocp.estimate`): in the phase's states
``x`` (:func:`.knots.state_map`), relative to the state's size as the estimate is,
``e_k = max_j |x_j(end) - x_j(q_k+1, qd_k+1)| / (1 + max_k |x_kj|)``; the value is the largest
``e_k / max(estimate_k, 1e-7)``. The estimate is a residual integral, not a bound: on the
measured grids (8 + 5 to 30 + 15 knots, 12-48 m/min, both transcriptions) the ratio stays below
5; the limit is 10. A file without estimates (written before they were stored) is checked
against the fixed limit 0.05 (rad, m, rates / 10) in full coordinates, as before.

``integration.phase`` (information) integrates each phase from its first knot and reports the
position drift at its end: the open-loop walk is unstable, so it grows with the phase.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import casadi as ca
import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from gaitopt.analysis.checks.check import LIMITS, Check, Worst
from gaitopt.analysis.checks.knots import state_map
from gaitopt.analysis.numeric import numeric_function
from gaitopt.dynamics.function_cache import disk_cached, function_file
from gaitopt.dynamics.functions import contact_dynamics_function
from gaitopt.gait.record.file import Gait, GaitPhase
from gaitopt.gait.sequence.contact_sequence import phase_holds
from gaitopt.robot.model import RobotModel

Array = NDArray[np.float64]

#: Limit of the full-coordinate interval error for files without an error estimate.
FIXED_INTERVAL_LIMIT = 5e-2
#: Smallest estimate a ratio is taken against (integration and rounding noise).
ESTIMATE_FLOOR = 1e-7


def _integrate(rhs: Callable[[float, Array], Array], t0: float, t1: float, y0: Array) -> Array:
    sol = solve_ivp(rhs, (t0, t1), y0, method="DOP853", rtol=1e-10, atol=1e-10)
    return np.asarray(sol.y[:, -1], dtype=float)


@functools.lru_cache(maxsize=32)
def _ode(model: RobotModel, contacts: tuple[str, ...]) -> ca.Function:
    """``(y, u0, u1, s) -> ydot`` for ``y = [q, qd]`` with the contacts held and the controls
    ``u = u0 + s (u1 - u0)`` (s in [0, 1] along an interval): one SX function (the contact
    dynamics inlined), evaluated through :func:`gaitopt.analysis.numeric.numeric_function`;
    cached on disk (:mod:`gaitopt.dynamics.function_cache`)."""

    def build() -> ca.Function:
        dyn = contact_dynamics_function(model, contacts, inputs="u")
        y = ca.SX.sym("y", 2 * model.nq)
        u0, u1 = ca.SX.sym("u0", model.nu), ca.SX.sym("u1", model.nu)
        s = ca.SX.sym("s")
        qdd = dyn(y[:model.nq], y[model.nq:], u0 + s * (u1 - u0))[0]
        return ca.Function("verify_ode", [y, u0, u1, s], [ca.vertcat(y[model.nq:], qdd)])

    return disk_cached(function_file("verify_ode", (model.content_hash(), contacts)), build)


def _interval_ends(gait: Gait, ph: GaitPhase, starts: Array | None) -> Array:
    """The state (2 nq,) at the end of each interval k (K-1 rows), integrated from
    ``starts[k]`` or, if ``starts`` is None, from the previous interval's end (the whole
    phase from its first knot)."""
    i = next(j for j, other in enumerate(gait.phases) if other is ph)
    ode = numeric_function(_ode(gait.model, phase_holds(gait.contact_sequence, i,
                                                         tuple(ph.contacts))))
    ends = []
    y = np.hstack([ph.q[0], ph.qd[0]])
    for k in range(ph.t.size - 1):
        t0, h = ph.t[k], ph.t[k + 1] - ph.t[k]
        u0, u1 = ph.u[k], ph.u[k + 1]

        def rhs(t: float, y: Array, t0: float = t0, h: float = h, u0: Array = u0,
                u1: Array = u1) -> Array:
            return ode(y, u0, u1, (t - t0) / h)[0].ravel()

        start = y if starts is None else starts[k]
        y = _integrate(rhs, t0, t0 + h, start)
        ends.append(y)
    return np.array(ends)


def integration_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    """``integration.interval`` and ``integration.phase`` (see the module docstring)."""
    model = gait.model
    nq = model.nq
    estimated = all(ph.error_estimate is not None for ph in gait.phases)
    interval, drift = Worst(), Worst()
    for i, ph in enumerate(gait.phases):
        if ph.interpolation["controls"] != "piecewise_linear":
            raise ValueError(f"phases[{i}].interpolation.controls: "
                             f"{ph.interpolation['controls']!r} is not supported")
        y = np.hstack([ph.q, ph.qd])
        ends = _interval_ends(gait, ph, y)
        if estimated:
            assert ph.error_estimate is not None
            to_states = state_map(model, tuple(ph.state_names))
            zeros = np.zeros((ends.shape[0], nq))
            x_end = np.asarray(to_states.map(ends.shape[0])(ends[:, :nq].T, ends[:, nq:].T,
                                                            zeros.T)[0], dtype=float).T
            x_knot = np.asarray(to_states.map(ph.t.size)(ph.q.T, ph.qd.T, ph.qdd.T)[0],
                                dtype=float).T
            size = 1.0 + np.max(np.abs(x_knot), axis=0)
            err = np.max(np.abs(x_end - x_knot[1:]) / size, axis=1)
            ratio = err / np.maximum(ph.error_estimate, ESTIMATE_FLOOR)
        else:
            ratio = np.array([max(np.max(np.abs(e[:nq] - b[:nq])),
                                  np.max(np.abs(e[nq:] - b[nq:])) / 10.0)
                              for e, b in zip(ends, y[1:], strict=True)])
        k = int(np.argmax(ratio))
        interval = interval.update(ratio[k], f"phases[{i}] ({ph.name}) interval {k}")
        whole = _interval_ends(gait, ph, None)[-1]
        drift = drift.update(float(np.max(np.abs(whole[:nq] - y[-1][:nq]))),
                             f"phases[{i}] ({ph.name})")
    if estimated:
        first = interval.check("integration.interval", lim)
    else:
        scale = lim["integration.interval"] / LIMITS["integration.interval"]
        first = Check("integration.interval", interval.value, FIXED_INTERVAL_LIMIT * scale,
                      interval.where + " (no error estimate in the file: fixed limit)",
                      unit_override="rad|m, rates / 10")
    return [first, drift.check("integration.phase", lim)]
