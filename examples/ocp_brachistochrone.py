"""Brachistochrone with gaitopt.ocp: minimum-time slide to a point, compared with the cycloid.

Run: ``python examples/ocp_brachistochrone.py [--intervals 20] [--tol 1e-8] [--plot out.png]``
"""

from __future__ import annotations

import argparse
import math

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from gaitopt.ocp import Duration, Guess, Phase, PhaseGuess, Problem, transcribe
from gaitopt.ocp.refine import refine

G = 9.81
X_END, Y_END = 1.0, 0.6  # target point (m), y measured downward


def main(argv: list[str] | None = None) -> float:
    """Solve, refine, compare with the cycloid; returns the relative error in the time."""
    args = argparse.ArgumentParser(description=__doc__)
    args.add_argument("--intervals", type=int, default=20)
    args.add_argument("--tol", type=float, default=1e-8)
    args.add_argument("--plot", default=None, help="save a figure to this PNG file")
    opts = args.parse_args(argv)

    # ---- States, controls and dynamics -----------------------------------------------------
    # x, y (m; y downward), speed v (m/s); control: path angle theta below horizontal (rad).
    def dynamics(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        v, theta = x[2], u[0]
        return ca.vertcat(v * ca.cos(theta), v * ca.sin(theta), G * ca.sin(theta))

    # ---- Bounds and boundary conditions ------------------------------------------------------
    slide = Phase(
        "slide", states=["x", "y", "v"], controls=["theta"], dynamics=dynamics,
        duration=Duration.free(0.05, 5.0),
        control_bounds={"theta": (-math.pi / 2, math.pi / 2)},
        initial_state={"x": 0.0, "y": 0.0, "v": 0.0},
        final_state={"x": X_END, "y": Y_END},
        intervals=opts.intervals)

    # ---- Objective: the final time (a Mayer term on the phase ends) ------------------------
    problem = Problem([slide], mayer=lambda ends, p: ends["slide"].tf)

    # ---- Initial guess: a straight line -------------------------------------------------------
    tau = np.array([0.0, 1.0])
    guess = Guess(phases={"slide": PhaseGuess(
        x={"x": X_END * tau, "y": Y_END * tau, "v": [1.0, 3.0]}, u={"theta": 0.5},
        tau=tau, duration=0.6)})

    # ---- Solve --------------------------------------------------------------------------------
    tr = transcribe(problem, method="hermite-simpson")
    first = tr.solve(guess)
    print("first solve:", first.summary())
    print("NLP size:", first.nlp_size)

    # ---- Mesh refinement until the error estimate meets the tolerance ---------------------
    refined = refine(problem, tol=opts.tol, intervals=opts.intervals, guess=first)
    res = refined.result
    print(f"refinement: intervals per round {refined.intervals}, "
          f"max error {res.max_error:.2e}, converged {refined.converged}")

    # ---- Post-processing: compare with the analytic cycloid --------------------------------
    phi_f = brentq(lambda f: (f - math.sin(f)) / (1 - math.cos(f)) - X_END / Y_END, 1e-6,
                   2 * math.pi - 1e-6)
    radius = Y_END / (1 - math.cos(phi_f))
    t_exact = phi_f * math.sqrt(radius / G)
    ph = res.phase("slide")
    phi = ph.t * math.sqrt(G / radius)
    path_err = np.max(np.hypot(ph.state("x") - radius * (phi - np.sin(phi)),
                               ph.state("y") - radius * (1 - np.cos(phi))))
    rel = abs(ph.duration - t_exact) / t_exact
    print(f"time {ph.duration:.10f} s (cycloid {t_exact:.10f} s, rel. error {rel:.1e}); "
          f"largest path error {path_err:.1e} m")

    if opts.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        tt = np.linspace(ph.t0, ph.tf, 400)
        xs = ph.x_at(tt)
        fig, ax = plt.subplots(figsize=(5, 3.5))
        ax.plot(radius * (tt * math.sqrt(G / radius) - np.sin(tt * math.sqrt(G / radius))),
                -radius * (1 - np.cos(tt * math.sqrt(G / radius))), "k-", lw=3, alpha=0.3,
                label="cycloid")
        ax.plot(xs[:, 0], -xs[:, 1], "C0-", label="Hermite-Simpson interpolant")
        ax.plot(ph.state("x"), -ph.state("y"), "C0o", ms=3, label="knots")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("height (m)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(opts.plot, dpi=120)
    return rel


if __name__ == "__main__":
    main()
