"""Benchmark of the gaitopt.ocp engine on the known-answer test problems.

For each problem, mesh size and evaluation mode it prints: build time (transcribe: NLP,
derivatives, solver and for compiled modes the C compilation, cold and warm cache), solve
wall time (best of ``--repeat``), time spent in function evaluations, IPOPT iterations,
evaluation counts by kind, the error of the objective against the analytic optimum, and the
ratio of solve and evaluation time to the interpreted SX mode measured in the same run.

Modes: ``sx`` (expand=True, CasADi VM), ``mx`` (expand=False, mapped point functions),
``codegen`` (MX compiled to C via gaitopt.codegen with -O2, cached; ``codegen-O1`` with -O1),
``codegen-sx`` (the expanded SX
NLP compiled: fast to evaluate, slow to compile), ``jit`` (CasADi jit of the SX NLP).

Run: ``python bench/ocp.py [--sizes 10 40 160] [--modes sx mx codegen] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "ocp"))

import problems as P  # noqa: E402

from gaitopt.ocp import Problem, transcribe  # noqa: E402

MODES: dict[str, dict[str, Any]] = {
    "sx": {"expand": True, "compiled": None},
    "mx": {"expand": False, "compiled": None},
    "codegen": {"expand": False, "compiled": "codegen"},
    "codegen-O1": {"expand": False, "compiled": "codegen",
                   "compile_flags": ("-O1", "-fPIC", "-shared")},
    "codegen-sx": {"expand": True, "compiled": "codegen"},
    "jit": {"expand": True, "compiled": "jit"},
}

R_CYC, _, T_CYC = P.cycloid(1.0, 0.6)
LINKS = 5


def heavy_chain(intervals: int) -> Problem:
    """A 5-link pendulum chain (10 states, 5 torques) with the mass matrix solved
    symbolically: point functions of a few thousand operations, like a biped's dynamics.
    Swing from hanging at rest to q = 0.5 rad at rest in 1 s with least int |u|^2.
    No analytic optimum (the error column is blank)."""
    import casadi as ca

    from gaitopt.ocp import Phase

    def f(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        q, qd = x[:LINKS], x[LINKS:]
        mass = ca.SX(LINKS, LINKS)
        bias = ca.SX(LINKS, 1)
        for i in range(LINKS):
            for j in range(LINKS):
                mij = LINKS - max(i, j)
                mass[i, j] = mij * ca.cos(q[i] - q[j])
                bias[i] += mij * ca.sin(q[i] - q[j]) * qd[j] ** 2
            bias[i] += 9.81 * (LINKS - i) * ca.sin(q[i])
        return ca.vertcat(qd, ca.solve(mass, u - bias))

    names = [f"q{i}" for i in range(LINKS)] + [f"qd{i}" for i in range(LINKS)]
    rest = {f"qd{i}": 0.0 for i in range(LINKS)}
    return Problem([Phase(
        "swing", names, [f"u{i}" for i in range(LINKS)], f, 1.0,
        initial_state={**{f"q{i}": 0.0 for i in range(LINKS)}, **rest},
        final_state={**{f"q{i}": 0.5 for i in range(LINKS)}, **rest},
        lagrange=lambda x, u, p, t: ca.sumsqr(u), intervals=intervals)])


# name -> (builder(intervals), guess or None, exact optimum)
PROBLEMS: dict[str, tuple[Callable[[int], Problem], Any, float]] = {
    "double_integrator": (P.double_integrator, None, 12.0),
    "brachistochrone": (lambda n: P.brachistochrone(intervals=n), P.brachistochrone_guess(),
                        T_CYC),
    "free_time": (P.free_time, None, 8.0 / math.sqrt(6.0)),
    "two_phase_jump": (P.two_phase_jump, None, 60.0 / 13.0),
    "periodic_ratio": (lambda n: P.periodic_ratio(intervals=n), None, 4.0),
    "heavy_chain": (heavy_chain, None, math.nan),
}


def run(name: str, n: int, mode: str, repeat: int) -> dict[str, Any]:
    """Build and solve one case; returns the measured figures."""
    build, guess, exact = PROBLEMS[name]
    t0 = time.perf_counter()
    tr = transcribe(build(n), **MODES[mode])
    t_build = time.perf_counter() - t0
    t_rebuild = float("nan")
    if MODES[mode]["compiled"] == "codegen":
        t0 = time.perf_counter()
        tr = transcribe(build(n), **MODES[mode])
        t_rebuild = time.perf_counter() - t0
    best = None
    for _ in range(repeat):
        res = tr.solve(guess)
        if best is None or res.times["total"] < best.times["total"]:
            best = res
    assert best is not None
    return {"problem": name, "N": n, "mode": mode, "build": t_build, "rebuild": t_rebuild,
            "solve": best.times["total"], "eval": best.times["evaluations"],
            "iters": best.iterations, "status": best.status, "counts": best.evaluations,
            "err": abs(best.objective - exact) / abs(exact), "size": best.nlp_size}


def main(argv: list[str] | None = None) -> list[dict[str, Any]]:
    """Run the grid and print the table; returns the rows."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--problems", nargs="+", default=list(PROBLEMS)[:-1],
                    choices=list(PROBLEMS))
    ap.add_argument("--sizes", nargs="+", type=int, default=[10, 40, 160])
    ap.add_argument("--modes", nargs="+", default=["sx", "mx", "codegen"], choices=list(MODES))
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    if "GAITOPT_CACHE" not in os.environ:
        os.environ["GAITOPT_CACHE"] = tempfile.mkdtemp(prefix="gaitopt-bench-")
    print(f"compiled-code cache: {os.environ['GAITOPT_CACHE']} (cold on first build)")
    header = (f"{'problem':18s} {'N':>4s} {'mode':11s} {'vars':>5s} {'build s':>8s} "
              f"{'rebuild':>8s} {'solve s':>8s} {'eval s':>8s} {'iter':>4s} "
              f"{'f/g/gf/jg/h calls':>20s} {'rel.err J':>9s} {'solve/sx':>8s} {'eval/sx':>8s}")
    print(header)
    print("-" * len(header))
    rows = []
    for name in args.problems:
        for n in args.sizes:
            ref = None
            for mode in args.modes:
                r = run(name, n, mode, args.repeat)
                rows.append(r)
                if mode == "sx":
                    ref = r
                c = r["counts"]
                calls = "/".join(str(c[k]) for k in ("nlp_f", "nlp_g", "nlp_grad_f",
                                                     "nlp_jac_g", "nlp_hess_l"))
                ratio = (f"{r['solve'] / ref['solve']:8.2f} {r['eval'] / ref['eval']:8.2f}"
                         if ref and ref["eval"] > 0 else f"{'-':>8s} {'-':>8s}")
                rebuild = "" if math.isnan(r["rebuild"]) else f"{r['rebuild']:8.3f}"
                print(f"{name:18s} {n:4d} {mode:11s} {r['size'].variables:5d} "
                      f"{r['build']:8.3f} {rebuild:>8s} {r['solve']:8.4f} {r['eval']:8.4f} "
                      f"{r['iters']:4d} {calls:>20s} {r['err']:9.1e} {ratio}".replace("nan", "  -")
                      + ("" if r["status"] == "Solve_Succeeded" else f"  {r['status']}"))
    return rows


if __name__ == "__main__":
    main()
