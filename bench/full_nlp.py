"""IPOPT's own time per iteration for variants of the full-coordinate walking NLP.

Where the time of a full-coordinate warm start goes, and which changes of the NLP's structure
shorten it (docs/results/benchmarks-gait.md, "Making the full-coordinate NLP smaller or sparser").
The script solves the five-link walk in full coordinates (paper control model, 12 m/min) or loads
``--gait FILE``, then warm-starts it at +5 % speed as ``bench/gait.py --targets`` does and
records what IPOPT got in that solve: the NLP, its options, the start point, the bounds and
the multipliers. It then solves that same start again for each variant below, every variant
as an expanded SX NLP, interleaved round by round (``--repeat`` rounds, the best kept), and
prints the NLP's size, the iterations, the objective and IPOPT's CPU time per iteration
without the NLP evaluations (``t_proc_total`` minus the five functions' ``t_proc``), which is
what a smaller or sparser KKT system would shorten:

* ``base``: the NLP as the transcription states it;
* ``free rows removed``: the rows whose bounds are both infinite (the held points at a phase's
  first knot, the clearances freed by ``full_stage_bounds``); the same problem;
* ``step length split``: one copy of the step length per interval of the defects, chained by
  equalities, so no column of the Jacobian and no row of the Hessian is dense; the same
  problem;
* ``base eliminated`` (with ``--stated`` only): the base's ``x, y`` and rates at the knots
  after a phase's first solved from the first held point's rows, which are removed: what
  ``full_problem`` does by default since 2026-12-02 (``place_base``); the same problem;
* ``step length fixed``: the step length held at its start (not the same problem; what
  removing its dense column could gain at most);
* ``no projection`` (with ``--stated`` only): the held-point rows removed and the projection
  controls fixed at 0 (not the same problem; what the projection costs).

    python bench/full_nlp.py [--knots 40,10] [--repeat 6] [--gait FILE] [--stated]

``--stated`` solves and measures the statement with every held-point row
(``full_problem(..., place_base=False)``, as before 2026-12-02) instead of the default.

The machine's load moves the absolute figures; the ratios to ``base`` in the same run are
the result.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import gaitopt.ocp.transcription as transcription  # noqa: E402
from gaitopt.gait.api import solve_staged_run  # noqa: E402
from gaitopt.gait.formulations.full import problem as full  # noqa: E402
from gaitopt.gait.formulations.full.problem import HELD, STEP_LENGTH  # noqa: E402
from gaitopt.gait.options.gait_options import GaitOptions  # noqa: E402
from gaitopt.gait.record.file import Gait  # noqa: E402
from gaitopt.gait.solve import transcriptions  # noqa: E402
from gaitopt.gait.solve.record import gait_from_run  # noqa: E402
from gaitopt.ocp.solver import EVAL_KINDS  # noqa: E402
from gaitopt.ocp.transcription import Transcription  # noqa: E402
from gaitopt.robot import load_model  # noqa: E402

SPEED = 0.2        # m/s, the paper's 12 m/min
SPEED_STEP = 1.05  # the warm start's speed change, as in bench/gait.py
ARG_KEYS = ("x0", "lbx", "ubx", "lbg", "ubg", "lam_x0", "lam_g0")


@dataclass
class Captured:
    """The last IPOPT call of a solve: its transcription, options and arguments."""

    tr: Transcription | None = None
    options: dict[str, Any] | None = None
    args: dict[str, np.ndarray] | None = None


@contextlib.contextmanager
def capturing() -> Iterator[Captured]:
    """Record the transcription, solver options and arguments of every IPOPT call."""
    out = Captured()
    solve, solver, call = Transcription.solve, Transcription.solver, transcription.call_solver

    def solve_(self: Transcription, *a: Any, **k: Any) -> Any:
        out.tr = self
        return solve(self, *a, **k)

    def solver_(self: Transcription, options: Any) -> Any:
        out.options = dict(options)
        return solver(self, options)

    def call_(s: Any, args: dict[str, Any]) -> Any:
        out.args = {k: np.asarray(args[k], dtype=float).ravel() for k in ARG_KEYS}
        return call(s, args)

    Transcription.solve = solve_  # type: ignore[method-assign]
    Transcription.solver = solver_  # type: ignore[method-assign]
    transcription.call_solver = call_  # type: ignore[assignment]
    try:
        yield out
    finally:
        Transcription.solve = solve  # type: ignore[method-assign]
        Transcription.solver = solver  # type: ignore[method-assign]
        transcription.call_solver = call  # type: ignore[assignment]


@dataclass
class Variant:
    """One NLP ``(x, f, g)`` (SX) with its solver arguments."""

    name: str
    same_problem: bool
    x: ca.SX
    f: ca.SX
    g: ca.SX
    args: dict[str, np.ndarray]


def without_rows(v: Variant, drop: np.ndarray, name: str, same: bool) -> Variant:
    """``v`` without the rows ``drop`` (indices of g)."""
    keep = np.ones(v.g.shape[0], dtype=bool)
    keep[drop] = False
    rows = [int(i) for i in np.flatnonzero(keep)]
    args = dict(v.args)
    for k in ("lbg", "ubg", "lam_g0"):
        args[k] = v.args[k][keep]
    return Variant(name, same, v.x, v.f, v.g[rows], args)


def fixed(v: Variant, index: np.ndarray, value: np.ndarray, name: str) -> Variant:
    """``v`` with the variables ``index`` fixed at ``value`` (scaled)."""
    args = {k: a.copy() for k, a in v.args.items()}
    for k in ("x0", "lbx", "ubx"):
        args[k][index] = value
    return Variant(name, False, v.x, v.f, v.g, args)


def split_step_length(v: Variant, tr: Transcription) -> Variant:
    """``v`` with one copy ``L_j`` of the step length per interval of the defects (both
    blocks of each phase), ``L_0 = L`` and ``L_{j+1} = L_j``: the same problem without a
    dense column."""
    i_l = tr.layout.parameter(STEP_LENGTH)
    g = [v.g[i] for i in range(v.g.shape[0])]
    groups: list[list[int]] = []
    for ph in tr.problem.phases:
        blocks = [tr.nlp.constraints.block(f"{ph.name}/{b}")
                  for b in ("defects", "midpoint defects")]
        intervals, n = blocks[0].shape
        for j in range(intervals):
            groups.append([b.rows.start + j * n + r for b in blocks for r in range(n)])
    copies = ca.SX.sym("L", len(groups))
    for j, rows in enumerate(groups):
        sub = ca.substitute(ca.vertcat(*[g[r] for r in rows]), v.x[i_l], copies[j])
        for k, r in enumerate(rows):
            g[r] = sub[k]
    chain = [copies[0] - v.x[i_l]] + [copies[j + 1] - copies[j] for j in range(len(groups) - 1)]
    m = len(groups)
    a = v.args
    args = dict(x0=np.r_[a["x0"], np.full(m, a["x0"][i_l])],
                lbx=np.r_[a["lbx"], np.full(m, -np.inf)], ubx=np.r_[a["ubx"], np.full(m, np.inf)],
                lbg=np.r_[a["lbg"], np.zeros(m)], ubg=np.r_[a["ubg"], np.zeros(m)],
                lam_x0=np.r_[a["lam_x0"], np.zeros(m)], lam_g0=np.r_[a["lam_g0"], np.zeros(m)])
    return Variant("step length split", True, ca.vertcat(v.x, copies), v.f,
                   ca.vertcat(*g, *chain), args)


def base_eliminated(v: Variant, tr: Transcription) -> Variant:
    """``v`` with the base's ``x, y, x_rate, y_rate`` at every knot where the held-point rows
    are enforced given by the rows of the phase's first held point, which are affine in them
    (the point is the base plus a function of the other coordinates): those four variables
    are fixed (IPOPT removes them), replaced by their expressions everywhere, and the four
    rows removed. Their box bounds go with them: the same problem where those bounds are
    inactive (they are at this walk's optimum)."""
    lbg = v.args["lbg"]
    names = ("x", "y", "x_rate", "y_rate")
    eliminated: list[int] = []
    expressions: list[Any] = []
    used: list[int] = []
    for ph, pf in zip(tr.problem.phases, tr.phase_functions, strict=True):
        if HELD not in [pr.name for pr in pf.path_rows]:
            continue
        pl = tr.layout.phase(ph.name)
        rows = tr.path_rows(ph.name, HELD)
        per = rows.size // pl.knots
        for k in range(pl.knots):
            chunk = rows[k * per:(k + 1) * per]
            if not np.isfinite(lbg[chunk[0]]):
                continue  # a phase's first knot: its rows are free
            picked = [int(chunk[0]), int(chunk[1]), int(chunk[per // 2]),
                      int(chunk[per // 2 + 1])]
            index = [pl.index("state", n, k) for n in names]
            base = ca.vertcat(*[v.x[i] for i in index])
            for r, i in zip(picked, index, strict=True):
                rest = ca.substitute(v.g[r], base, ca.DM.zeros(4))
                slope = ca.substitute(ca.jacobian(v.g[r], v.x[i]), base, ca.DM.zeros(4))
                eliminated.append(i)
                expressions.append(-rest / slope)
            used.extend(picked)
    xs = ca.vertcat(*[v.x[i] for i in eliminated])
    f, g = ca.substitute([v.f, v.g], [xs], [ca.vertcat(*expressions)])
    out = without_rows(Variant("base eliminated", True, v.x, f, g, v.args), np.array(used),
                       "base eliminated", True)
    for k in ("x0", "lbx", "ubx"):
        out.args[k] = out.args[k].copy()
        out.args[k][eliminated] = v.args["x0"][eliminated]
    return out


def variants(tr: Transcription, args: dict[str, np.ndarray]) -> list[Variant]:
    """The variants of the module docstring, from the captured NLP and arguments."""
    expanded = ca.Function("nlp", [tr.nlp.w_hat], [tr.nlp.f, tr.nlp.g]).expand()
    x = ca.SX.sym("w", tr.layout.size)
    f, g = expanded(x)
    base = Variant("base", True, x, f, g, args)
    free = np.flatnonzero(~np.isfinite(args["lbg"]) & ~np.isfinite(args["ubg"]))
    held = np.concatenate([
        tr.path_rows(ph.name, HELD)
        for ph, pf in zip(tr.problem.phases, tr.phase_functions, strict=True)
        if HELD in [pr.name for pr in pf.path_rows]])
    projection = np.concatenate([
        np.arange(tr.layout.size)[tr.layout.phase(ph.name).across_knots("control", c)]
        for ph in tr.problem.phases for c in ph.controls if c.startswith(("gamma_", "nu_"))])
    i_l = np.array([tr.layout.parameter(STEP_LENGTH)])
    no_projection = fixed(without_rows(base, held, "", False), projection,
                          np.zeros(projection.size), "no projection")
    # With the base placed, the stance point's projection cannot be removed alone.
    stated = [] if tr.nlp.dependent.size else [base_eliminated(base, tr), no_projection]
    return [base, without_rows(base, free, "free rows removed", True),
            split_step_length(base, tr), fixed(base, i_l, args["x0"][i_l], "step length fixed"),
            *stated]


def capture(knots: tuple[int, int], gait_file: Path) -> Captured:
    """The warm start from ``gait_file`` at +5 % speed, recorded."""
    model = load_model("five-link")
    options = GaitOptions.paper(speed=SPEED * SPEED_STEP, knots=knots, formulation="full",
                                transcription="hermite-simpson-separated")
    with capturing() as out:
        solution = solve_staged_run(model, options, warm_start=Gait.load(gait_file))
    print(f"warm start: {solution.result.iterations} iterations, J {solution.result.objective:.6f}")
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--knots", default="40,10", help="knots per phase, single,double")
    parser.add_argument("--repeat", type=int, default=6, help="interleaved rounds (best kept)")
    parser.add_argument("--gait", type=Path, help="a saved full-coordinate gait (default: solve)")
    parser.add_argument("--stated", action="store_true",
                        help="every held-point row stated (place_base=False)")
    a = parser.parse_args(argv)
    cache = tempfile.TemporaryDirectory()
    if a.stated:
        original = full.full_problem
        full.full_problem = (  # type: ignore[assignment]
            lambda m, o, s: original(m, o, s, place_base=False))
        # The problem's symbolic functions are cached on disk by options, not by statement.
        transcriptions.functions_file = (  # type: ignore[assignment]
            lambda key: Path(cache.name) / f"{abs(hash(key))}.pickle")
    k = [int(v) for v in a.knots.split(",")]
    if len(k) != 2 or min(k) < 2:
        parser.error(f"--knots: two integers >= 2, e.g. 40,10, got {a.knots!r}")
    knots = (k[0], k[1])
    with tempfile.TemporaryDirectory() as tmp:
        gait_file = a.gait
        if gait_file is None:
            model = load_model("five-link")
            options = GaitOptions.paper(speed=SPEED, knots=knots, formulation="full",
                                        transcription="hermite-simpson-separated")
            gait_file = Path(tmp) / "start.gait.json"
            gait_from_run(solve_staged_run(model, options)).save(gait_file)
        cap = capture(knots, gait_file)
    assert cap.tr is not None and cap.options is not None and cap.args is not None
    options = {k: v for k, v in cap.options.items() if k != "expand"}
    runs = [(v, ca.nlpsol(v.name.replace(" ", "_"), "ipopt", {"x": v.x, "f": v.f, "g": v.g},
                          options)) for v in variants(cap.tr, cap.args)]
    best: dict[str, float] = {}
    seen: dict[str, tuple[int, float, str]] = {}
    for _ in range(a.repeat):
        for v, solver in runs:
            out = solver(**v.args)
            st = solver.stats()
            evals = sum(float(st.get(f"t_proc_{n}", 0.0)) for n in EVAL_KINDS)
            per_it = (float(st["t_proc_total"]) - evals) / max(int(st["iter_count"]), 1)
            best[v.name] = min(best.get(v.name, np.inf), per_it)
            seen[v.name] = (int(st["iter_count"]), float(out["f"]), str(st["return_status"]))
    load = os.getloadavg()[0]
    print(f"\n{a.knots} knots, best of {a.repeat} interleaved rounds, load average {load:.1f}")
    print("| variant | same problem | variables (not fixed) | constraints | Jacobian nnz "
          "| Hessian nnz "
          "| iterations | objective (scaled) | IPOPT CPU ms / iteration | / base |")
    print("| --- | :---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    ref = best["base"]
    for v, solver in runs:
        jac = solver.get_function("nlp_jac_g").sparsity_out(1).nnz()
        hess = solver.get_function("nlp_hess_l").sparsity_out(0).nnz()
        it, obj, status = seen[v.name]
        mark = "" if status == "Solve_Succeeded" else f" ({status})"
        free_vars = int(np.sum(v.args["lbx"] != v.args["ubx"]))
        print(f"| {v.name} | {'yes' if v.same_problem else 'no'} | {free_vars} | "
              f"{v.g.shape[0]} | {jac} | {hess} | {it}{mark} | {obj:.10f} | "
              f"{best[v.name] * 1e3:.2f} | {best[v.name] / ref:.2f} |")


if __name__ == "__main__":
    main()
