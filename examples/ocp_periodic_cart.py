"""A periodic two-phase motion with parameters, linkages and a ratio cost (gaitopt.ocp).

A cart with drag (s' = v, v' = a - v) moves periodically over a distance D at mean speed vbar
in two phases whose durations are expressions of the parameters, T_i = D / (2 vbar) (like a
gait's phase times T = fraction * L / v). The cost is energy plus a constant c per second,
per unit distance: J = int (a^2 + c) dt / D. The optimum for a fixed vbar is
J = vbar + c / vbar (constant speed), and the best speed is vbar = sqrt(c).

Run: ``python examples/ocp_periodic_cart.py [--intervals 10] [--c 4]``
"""

from __future__ import annotations

import argparse
import math

import casadi as ca
import numpy as np

from gaitopt.ocp import (
    BoundaryConstraint,
    ControlLinkage,
    Duration,
    Linkage,
    Parameter,
    Phase,
    Problem,
    named,
    transcribe,
)

PARAMETERS = ["D", "vbar"]


def main(argv: list[str] | None = None) -> float:
    """Solve for the best speed, then sweep fixed speeds; returns the largest error in J."""
    args = argparse.ArgumentParser(description=__doc__)
    args.add_argument("--intervals", type=int, default=10)
    args.add_argument("--c", type=float, default=4.0)
    opts = args.parse_args(argv)
    c = opts.c

    # ---- Parameters ---------------------------------------------------------------------------
    parameters = [Parameter("D", 1.0, 1.0), Parameter("vbar", 0.2, 10.0, guess=1.0)]

    # ---- Dynamics and running cost (the same in both phases) -------------------------------
    def dynamics(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        return ca.vertcat(x[1], u[0] - x[1])

    def running_cost(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        return u[0] ** 2 + c

    # ---- Phases: durations are expressions of the parameters ------------------------------
    def half_period(p: ca.SX) -> ca.SX:
        q = named(p, PARAMETERS)
        return 0.5 * q["D"] / q["vbar"]

    phases = [Phase(name, ["s", "v"], ["a"], dynamics, Duration.of_parameters(half_period),
                    state_bounds={"v": (-10.0, 10.0)}, lagrange=running_cost,
                    intervals=opts.intervals,
                    initial_state={"s": 0.0} if name == "first" else {})
              for name in ("first", "second")]

    # ---- Linkages: continuity between the phases, periodicity of v and a -------------------
    linkages = [Linkage("first", "second"), ControlLinkage("first", "second"),
                Linkage("second", "first", states=["v"], name="periodic v"),
                ControlLinkage("second", "first", name="periodic a")]

    # ---- Boundary constraint: one period covers the distance D -------------------------------
    def distance(ends, p):  # type: ignore[no-untyped-def]
        return ends["second"].xf_named()["s"] - ends["first"].x0_named()["s"] - p[0]

    # ---- Objective: a ratio, (energy + c T) / D -------------------------------------------------
    problem = Problem(phases, parameters=parameters, linkages=linkages,
                      boundary_constraints=[BoundaryConstraint("distance", distance)],
                      cost_denominator=lambda ends, p: p[0])

    # ---- Solve with the speed free ---------------------------------------------------------------
    tr = transcribe(problem)
    best = tr.solve()
    print("free speed:", best.summary())
    print(f"  vbar = {best.parameters['vbar']:.8f} (exact {math.sqrt(c):.8f}), "
          f"J = {best.objective:.8f} (exact {2 * math.sqrt(c):.8f})")
    worst = abs(best.objective - 2 * math.sqrt(c))

    # ---- Re-solve the same NLP for fixed speeds (bounds only, nothing rebuilt) -------------
    previous = best
    for vbar in np.linspace(0.5, 4.0, 8):
        res = tr.solve(previous, parameters={"vbar": float(vbar)})
        exact = vbar + c / vbar
        worst = max(worst, abs(res.objective - exact))
        print(f"  vbar = {vbar:4.2f}: J = {res.objective:.8f} (exact {exact:.8f}), "
              f"{res.iterations} iterations, {res.status}")
        previous = res
    print(f"builds: {dict(tr.builds)} (one NLP, one solver for all solves)")
    return worst


if __name__ == "__main__":
    main()
