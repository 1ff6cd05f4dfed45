"""A transcription owns the NLP of a problem on a mesh and its solvers; solving returns a Result.

``transcribe(problem, method=..., intervals=...)`` validates the statement and builds the NLP
and the IPOPT solver once. ``tr.solve(guess, bounds=..., parameters=..., options=...)`` can be
called many times with other initial guesses and bounds without rebuilding anything (the
counters in ``tr.builds`` show it); only new solver options build (and cache) a new solver.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping, Sequence
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt import codegen
from gaitopt.ocp import pointwise
from gaitopt.ocp.bounds import Bounds, variable_bounds
from gaitopt.ocp.estimate import interval_errors
from gaitopt.ocp.functions import (
    EndsFunction,
    PhaseFunction,
    build_ends_function,
    build_phase_function,
)
from gaitopt.ocp.guess import Guess, WarmStart, guess_vector
from gaitopt.ocp.layout import Layout
from gaitopt.ocp.mesh import IntervalsSpec, Mesh, make_mesh
from gaitopt.ocp.nlp import Nlp, assemble, assemble_expressions
from gaitopt.ocp.pointwise import PointwiseNlp
from gaitopt.ocp.problem import Problem
from gaitopt.ocp.regrid import regridded
from gaitopt.ocp.result import METHODS, NlpSize, PhaseTrajectory, Result, point_values
from gaitopt.ocp.scaling import state_scales, variable_scales
from gaitopt.ocp.solver import (
    COMPILED_MODES,
    DEFAULT_OPTIONS,
    EVAL_KINDS,
    SolverOutput,
    call_solver,
    exact_hessian,
    make_solver,
    merge_options,
    nlp_symbols,
    options_key,
    solver_from_functions,
    solver_sharing_derivatives,
)
from gaitopt.ocp.validate import ProblemError, check_problem

Array = NDArray[np.float64]

ParameterBounds = Mapping[str, float | tuple[float, float]]

#: IPOPT options of a solve started with multipliers (``warm_start_multipliers``): the start
#: is a solution of a neighbouring problem, so it is kept (tiny pushes off the bounds) and the
#: barrier starts small. They override the ``options`` of :meth:`Transcription.solve`;
#: its ``warm_start_options`` override them.
WARM_START_OPTIONS: dict[str, Any] = {"ipopt.warm_start_init_point": "yes",
                                      "ipopt.warm_start_bound_push": 1e-9,
                                      "ipopt.warm_start_mult_bound_push": 1e-9,
                                      "ipopt.mu_init": 1e-6}


class Transcription:
    """The NLP of ``problem`` transcribed by ``method`` on ``mesh``, with cached solvers.

    Attributes:
        problem, method (name), mesh (normalised knots per phase), midpoint_bounds (state
        bounds at the separated form's midpoints), layout (w), nlp
        (symbolic NLP with constraint layout and scales), builds (Counter: ``nlp``,
        ``solver``), options (the default solver options).
    """

    def __init__(self, problem: Problem, method: str, mesh: Mesh, *, expand: bool | None = None,
                 compiled: str | None = None, options: Mapping[str, Any] | None = None,
                 scaling: bool = True, cse: bool = True,
                 compile_flags: Sequence[str] | None = None, build_solver: bool = True,
                 midpoint_bounds: bool = True,
                 functions: tuple[tuple[PhaseFunction, ...], EndsFunction] | None = None
                 ) -> None:
        check_problem(problem)
        if method not in METHODS:
            raise ProblemError(f"method must be one of {list(METHODS)}, got {method!r}")
        if compiled not in COMPILED_MODES:
            raise ProblemError(f"compiled must be one of {COMPILED_MODES}, got {compiled!r}")
        self.problem = problem
        self.method = method
        self.mesh = mesh
        self.compiled = compiled
        self.compile_flags = tuple(compile_flags) if compile_flags else codegen.DEFAULT_FLAGS
        # Default: SX (expanded) when interpreted; MX with mapped SX point functions when
        # compiled, whose C code has loops over the grid and compiles in a time independent of
        # the mesh size (see docs/ocp.md for measurements).
        self.expand = (compiled is None) if expand is None else expand
        self.options = merge_options(DEFAULT_OPTIONS, options)
        self.builds: Counter[str] = Counter()
        n_p = len(problem.parameters)
        self.layout = Layout.build(
            [(ph.name, ph.states, ph.controls, tau.size, ph.duration_spec().kind == "free")
             for ph, tau in zip(problem.phases, mesh, strict=True)], problem.parameter_names,
            midpoint_states=METHODS[method].midpoint_variables)
        sx = tuple(state_scales(ph, scaling) for ph in problem.phases)
        if functions is None:
            self.phase_functions: tuple[PhaseFunction, ...] = tuple(
                build_phase_function(ph, n_p, cse=cse) for ph in problem.phases)
            ends = build_ends_function(problem, {ph.name: s for ph, s in
                                                 zip(problem.phases, sx, strict=True)}, cse=cse)
        else:
            self.phase_functions, ends = functions
        #: The problem's symbolic functions, which do not depend on the mesh: another
        #: transcription of the same problem (and scaling, cse) may take them (``functions``).
        self.functions: tuple[tuple[PhaseFunction, ...], EndsFunction] = (
            self.phase_functions, ends)
        d_w = variable_scales(problem, self.layout, scaling)
        self._state_scales = sx
        self.nlp: Nlp = assemble(problem, METHODS[method], mesh, self.layout,
                                 self.phase_functions, ends, d_w, sx)
        self.midpoint_bounds = midpoint_bounds
        lbw, ubw = variable_bounds(problem, self.layout, midpoint_bounds)
        self._bounds = Bounds(self.layout, self.nlp.constraints, lbw, ubw, self.nlp.lbg,
                              self.nlp.ubg, midpoint_bounds)
        self._bounds.check()
        self._pointwise: PointwiseNlp | None = None
        if compiled == "points":
            has_mid = any(pf.midpoint_rows.size > 0 for pf in self.phase_functions)
            if not pointwise.supports(METHODS[method], has_mid):
                raise ProblemError(f"compiled='points' needs a method that evaluates the "
                                   f"dynamics at single grid points (hermite-simpson-separated,"
                                   f" or trapezoidal without midpoint path constraints), not "
                                   f"{method!r}")
            self._pointwise = self.pointwise_nlp()
            self._symbols = nlp_symbols(self.nlp.w_hat, self.nlp.f, self.nlp.g, False)
        else:
            self._symbols = nlp_symbols(self.nlp.w_hat, self.nlp.f, self.nlp.g, self.expand)
        self.builds["nlp"] += 1
        # Solvers by options, and whether each has the exact Hessian (see solver()).
        self._solvers: dict[str, tuple[ca.Function, bool]] = {}
        if build_solver:
            self.solver(self.options)

    def pointwise_nlp(self, *, interval_templates: bool | None = None, compile_c: bool = True
                      ) -> PointwiseNlp:
        """The solver functions of ``compiled="points"`` (:mod:`gaitopt.ocp.pointwise`):
        with ``interval_templates`` the terms of the intervals come from functions of one
        interval derived once per process and mapped over the mesh, else they are derived
        within the outer functions of this mesh (the same NLP). Default: templates on a mesh
        of at least :data:`gaitopt.ocp.pointwise.TEMPLATE_MIN_INTERVALS` intervals, where
        deriving costs more than the templates' fixed cost per evaluation."""
        if interval_templates is None:
            intervals = sum(pl.intervals for pl in self.layout.phases)
            interval_templates = intervals >= pointwise.TEMPLATE_MIN_INTERVALS
        recorder = pointwise.PointRecorder()
        ends = self.functions[1]
        extra: dict[str, Any] = ({"interval_calls": recorder.intervals}
                                 if interval_templates else {})
        outer = assemble_expressions(self.problem, METHODS[self.method], self.mesh,
                                     self.layout, self.phase_functions, ends, self.nlp.d_w,
                                     self._state_scales, symbols=ca.SX, point_calls=recorder,
                                     ends_call=recorder.ends, fold_knot_states=True, **extra)
        return pointwise.build_pointwise(outer, recorder.groups, compile_c=compile_c,
                                         intervals=recorder.interval_groups)

    # -- solvers ---------------------------------------------------------------------------
    def solver(self, options: Mapping[str, Any]) -> ca.Function:
        """The (cached) IPOPT solver for ``options``, built on first use.

        The first solver of each Hessian mode derives the NLP's derivative functions (for a
        large expanded NLP most of that time goes to the exact Hessian of the Lagrangian,
        which a limited-memory solver never derives); later solvers with other options
        share them (:func:`solver_sharing_derivatives`)."""
        key = options_key(options)
        if key not in self._solvers:
            name = f"ocp_solver_{len(self._solvers)}"
            exact = exact_hessian(options)
            base = next((fn for fn, ex in self._solvers.values() if ex == exact), None)
            if self._pointwise is not None:
                solver = solver_from_functions(name, self._pointwise.functions,
                                               self.layout.size, dict(options))
            elif base is not None:
                solver = solver_sharing_derivatives(name, base, self.layout.size,
                                                    dict(options))
            else:
                solver = make_solver(name, self._symbols, dict(options), self.compiled,
                                     self.compile_flags)
            self._solvers[key] = (solver, exact)
            self.builds["solver"] += 1
        return self._solvers[key][0]

    # -- bounds and guesses ----------------------------------------------------------------
    def path_rows(self, phase: str, name: str) -> NDArray[np.int64]:
        """Rows of g holding path constraint ``name`` of ``phase`` at every knot (and
        midpoint, if it is imposed there), e.g. to relax it with ``Bounds.with_rows``."""
        i = self.problem.phase_index(phase)
        pf = self.phase_functions[i]
        match = [pr for pr in pf.path_rows if pr.name == name]
        if not match:
            raise ProblemError(f"phase {phase!r} has no path constraint {name!r} (it has "
                               f"{[pr.name for pr in pf.path_rows]})")
        within = np.arange(pf.n_path)[match[0].rows]
        out = []
        knots = self.nlp.constraints.block(f"{phase}/path@knots")
        n_knots = knots.shape[0]
        for k in range(n_knots):
            out.extend(knots.rows.start + k * pf.n_path + within)
        mids = [b for b in self.nlp.constraints.blocks if b.name == f"{phase}/path@midpoints"]
        if mids:
            mr = list(pf.midpoint_rows)
            within_mid = [mr.index(j) for j in within if j in mr]
            for k in range(mids[0].shape[0]):
                out.extend(mids[0].rows.start + k * len(mr) + np.asarray(within_mid, dtype=int))
        return np.asarray(out, dtype=np.int64)

    def bounds(self) -> Bounds:
        """The statement's bounds (modify with ``Bounds.with_*`` and pass to :meth:`solve`)."""
        return self._bounds

    def initial_guess(self, guess: Guess | Result | WarmStart | None = None) -> Array:
        """The unscaled initial point w0 for ``guess``."""
        if isinstance(guess, WarmStart):
            if not guess.fits(self.layout, self.method, self.nlp.lbg.size):
                raise ProblemError("warm start: made for another transcription (layout, "
                                   "method or constraints differ)")
            return np.array(guess.w, dtype=float)
        return guess_vector(self.problem, self.layout, self.mesh, guess)

    def nlp_size(self, bounds: Bounds | None = None) -> NlpSize:
        """Variables and constraints counted in the paper's terms (see :class:`NlpSize`)."""
        b = bounds or self._bounds
        fixed = b.lbw == b.ubw
        fixed[self.nlp.dependent] = True  # given by KnotStates: no unknowns
        boxed = (~fixed) & (np.isfinite(b.lbw) | np.isfinite(b.ubw))
        eq = b.lbg == b.ubg
        ineq = (~eq) & (np.isfinite(b.lbg) | np.isfinite(b.ubg))
        return NlpSize(self.layout.size, int(fixed.sum()), int(boxed.sum()), int(eq.sum()),
                       int(ineq.sum()))

    # -- solving ---------------------------------------------------------------------------
    def solve(self, guess: Guess | Result | WarmStart | None = None, *,
              bounds: Bounds | None = None,
              parameters: ParameterBounds | None = None,
              options: Mapping[str, Any] | None = None,
              warm_start_multipliers: bool = False,
              warm_start_options: Mapping[str, Any] | None = None,
              regrid: bool = False) -> Result:
        """Solve the NLP from ``guess``; never raises for solver failures.

        ``bounds`` replaces the statement's bounds; ``parameters`` then bounds parameters by
        name (a value fixes it, a pair bounds it). ``options`` are merged over the
        transcription's solver options. ``warm_start_multipliers`` passes a Result's
        multipliers to IPOPT when its layout matches (a :class:`WarmStart` must match; values
        and multipliers are taken as they are), and then :data:`WARM_START_OPTIONS` with
        ``warm_start_options`` merged over them apply, over ``options``. With ``regrid`` too,
        a Result on another grid of this problem (same method) passes its multipliers mapped
        onto this grid (:func:`gaitopt.ocp.regrid.regridded`; a Result of another problem
        is a ProblemError). A Result of the same variables with other constraint blocks
        passes its multipliers by block name (:meth:`carried_over`)."""
        b = bounds or self._bounds
        if b.layout.signature() != self.layout.signature() or b.lbg.size != self.nlp.lbg.size:
            raise ProblemError("bounds: made for another transcription (layout differs)")
        for name, val in (parameters or {}).items():
            lo, hi = val if isinstance(val, tuple) else (val, val)
            try:
                b = b.with_parameter(name, lo, hi)
            except KeyError as exc:
                raise ProblemError(str(exc.args[0])) from None
        b.check()
        opts = merge_options(self.options, options)
        if warm_start_multipliers:
            guess = self._multiplier_start(guess, regrid)
        w0 = self.initial_guess(guess)
        d_w, d_g, s_j = self.nlp.d_w, self.nlp.d_g, self.nlp.objective_scale
        args: dict[str, Any] = dict(x0=w0 / d_w, lbx=b.lbw / d_w, ubx=b.ubw / d_w,
                                    lbg=b.lbg / d_g, ubg=b.ubg / d_g)
        dep = self.nlp.dependent
        if dep.size:
            # Variables the NLP does not read (KnotStates give their values): fixed, so
            # IPOPT removes them; their bounds are checked on the result instead.
            held = np.nan_to_num(args["x0"][dep], nan=0.0, posinf=0.0, neginf=0.0)
            args["x0"] = args["x0"].copy()
            args["x0"][dep] = held
            args["lbx"], args["ubx"] = args["lbx"].copy(), args["ubx"].copy()
            args["lbx"][dep] = args["ubx"][dep] = held
        if warm_start_multipliers and self._has_multipliers(guess):
            assert isinstance(guess, Result | WarmStart)
            args["lam_x0"] = guess.lam_x * d_w / s_j
            args["lam_g0"] = guess.lam_g * d_g / s_j
            opts = merge_options(opts, WARM_START_OPTIONS, warm_start_options)
        try:
            solver = self.solver(opts)
        except Exception as exc:  # noqa: BLE001 - bad options etc.: report, don't raise
            out = SolverOutput(w0 / d_w, np.zeros_like(w0), np.zeros(d_g.size), math.nan, {},
                               f"{type(exc).__name__}: {str(exc).strip()[-500:]}")
        else:
            out = call_solver(solver, args)
        return self._result(out, b)

    def restarts(self, guess: Guess | Result | WarmStart | None, *, regrid: bool = False
                 ) -> bool:
        """Whether :meth:`solve` with ``warm_start_multipliers`` (and ``regrid``) passes the
        multipliers of ``guess`` to IPOPT, so that :data:`WARM_START_OPTIONS` and the
        ``warm_start_options`` apply: a :class:`WarmStart`, or a Result of this layout and
        method (of other constraint blocks: carried over by name; of another grid: only
        with ``regrid``)."""
        return self._has_multipliers(self._multiplier_start(guess, regrid))

    def _multiplier_start(self, guess: Guess | Result | WarmStart | None, regrid: bool
                          ) -> Guess | Result | WarmStart | None:
        """``guess`` as :meth:`solve` starts from it with multipliers: a Result of another
        grid regridded (with ``regrid``), one of other constraint blocks carried over."""
        if (regrid and isinstance(guess, Result)
                and guess.layout_signature != self.layout.signature()):
            guess = regridded(self, guess)
        if (isinstance(guess, Result) and guess.constraint_blocks
                and guess.layout_signature == self.layout.signature()
                and guess.method == self.method
                and guess.constraint_blocks != self.constraint_blocks):
            guess = self.carried_over(guess)
        return guess

    def _has_multipliers(self, guess: Guess | Result | WarmStart | None) -> bool:
        """Whether ``guess`` (as :meth:`_multiplier_start` made it) carries multipliers of
        this NLP's layout."""
        return isinstance(guess, WarmStart) or (
            isinstance(guess, Result) and guess.layout_signature == self.layout.signature()
            and guess.method == self.method and guess.lam_g.size == self.nlp.d_g.size)

    @property
    def constraint_blocks(self) -> tuple[tuple[str, int], ...]:
        """``(name, rows)`` of each block of ``g``, in order."""
        return tuple((b.name, b.rows.stop - b.rows.start) for b in self.nlp.constraints.blocks)

    def carried_over(self, result: Result) -> WarmStart:
        """The solution ``result`` of a problem with this transcription's variables and method
        but other constraint blocks (one with constraints added or left out, e.g. a liftoff
        impulse's rows) as a start of this one: its values and variable multipliers as they
        are, each constraint block's multipliers from the block of the same name and size
        (0 for a block ``result`` lacks). Where the added constraints hold at ``result``
        with zero multipliers it is a KKT point of this problem, and IPOPT restarts there as
        from its own solution.

        Raises:
            ProblemError: ``result`` has other variables or another method, or no block
                names.
        """
        if (result.layout_signature != self.layout.signature() or result.method != self.method
                or not result.constraint_blocks):
            raise ProblemError("carried_over: the result is of other variables or method")
        source: dict[str, slice] = {}
        start = 0
        for name, size in result.constraint_blocks:
            source[name] = slice(start, start + size)
            start += size
        lam_g = np.zeros(self.nlp.lbg.size)
        for block in self.nlp.constraints.blocks:
            rows = source.get(block.name)
            if rows is not None and rows.stop - rows.start == block.rows.stop - block.rows.start:
                lam_g[block.rows] = result.lam_g[rows]
        return WarmStart(w=np.asarray(result.w, dtype=float),
                         lam_x=np.asarray(result.lam_x, dtype=float), lam_g=lam_g,
                         layout=repr(self.layout.signature()), method=self.method)

    def result_at(self, start: WarmStart) -> Result:
        """The :class:`~gaitopt.ocp.Result` of this transcription at the NLP point and
        multipliers ``start`` (a solution kept in a file, unscaled as a Result holds them),
        without solving: its trajectories, parameters and multipliers, e.g. to map it onto
        another grid (:func:`gaitopt.ocp.regrid.regridded`). Its status says so
        (``not solved``, not a success).

        Raises:
            ProblemError: ``start`` was made for another transcription (layout, method or
                constraint count differ).
        """
        if not start.fits(self.layout, self.method, self.nlp.lbg.size):
            raise ProblemError("start: made for another transcription (layout differs)")
        n = self.nlp
        out = SolverOutput(start.w / n.d_w, start.lam_x * n.d_w / n.objective_scale,
                           start.lam_g * n.d_g / n.objective_scale, math.nan,
                           {"return_status": "not solved"}, None)
        return self._result(out, self._bounds)

    def _result(self, out: SolverOutput, b: Bounds) -> Result:
        nlp = self.nlp
        w = out.x * nlp.d_w
        if nlp.dependent.size:
            w[nlp.dependent] = np.asarray(nlp.knot_states(w), dtype=float).ravel()
        lam_x = out.lam_x * nlp.objective_scale / nlp.d_w
        lam_g = out.lam_g * nlp.objective_scale / nlp.d_g
        g, num, den, durs = (np.asarray(v, dtype=float).ravel() for v in nlp.evaluate(w))
        objective = float(num[0] / den[0]) if self.nlp_has_ratio else float(num[0])
        viol = 0.0
        if g.size:
            viol = max(viol, float(np.max(np.maximum(b.lbg - g, g - b.ubg), initial=0.0)))
        viol = max(viol, float(np.max(np.maximum(b.lbw - w, w - b.ubw), initial=0.0)))
        p = w[self.layout.parameter_slice()]
        phases = []
        t_start = self.problem.t0
        method = METHODS[self.method]
        for ph, pl, pf, tau, T in zip(self.problem.phases, self.layout.phases,
                                      self.phase_functions, self.mesh, durs, strict=True):
            t = t_start + T * tau
            x = w[pl.state_indices()]
            u = w[pl.control_indices()]
            point = (pf.point if self._pointwise is None
                     else self._pointwise.evaluator(pf.point))
            xdot, path, _ = point_values(point, t, x, u, p)
            if np.all(np.isfinite(x)) and np.all(np.isfinite(xdot)) and T > 0:
                eta, err = interval_errors(method, point, t, x, u, xdot, p)
            else:
                eta, err = np.full((tau.size - 1, ph.n_states), np.nan), np.full(tau.size - 1,
                                                                                 np.nan)
            x_mid = w[pl.midpoint_indices()] if pl.midpoints else None
            phases.append(PhaseTrajectory(
                ph.name, tuple(ph.states), tuple(ph.controls), self.method, t, x, u, xdot,
                {pr.name: path[:, pr.rows] for pr in pf.path_rows}, err, eta, x_mid))
            t_start = t_start + T
        st = out.stats
        status = str(st.get("return_status", "unknown")) if out.error is None else \
            "Solver_Exception"
        evals = {k: int(st.get(f"n_call_{k}", 0)) for k in EVAL_KINDS}
        times = {k: float(st.get(f"t_wall_{k}", 0.0)) for k in EVAL_KINDS}
        times["evaluations"] = sum(times[k] for k in EVAL_KINDS)
        times["total"] = float(st.get("t_wall_total", 0.0))
        success = bool(st.get("success", False)) and out.error is None
        return Result(
            status=status, success=success, iterations=int(st.get("iter_count", 0)),
            objective=objective, constraint_violation=viol, evaluations=evals, times=times,
            nlp_size=self.nlp_size(b), phases=tuple(phases),
            parameters={name: float(p[i]) for i, name in enumerate(self.layout.parameters)},
            w=w, lam_x=lam_x, lam_g=lam_g, method=self.method, mesh=self.mesh,
            layout_signature=self.layout.signature(), message=out.error or status,
            constraint_blocks=self.constraint_blocks,
            stats={k: v for k, v in st.items() if not isinstance(v, dict | list)})

    @property
    def nlp_has_ratio(self) -> bool:
        """Whether the objective is a ratio (a cost denominator is given)."""
        return self.problem.cost_denominator is not None


def transcribe(problem: Problem, *, method: str = "hermite-simpson",
               intervals: IntervalsSpec | Mapping[str, IntervalsSpec] | None = None,
               expand: bool | None = None, compiled: str | None = None,
               options: Mapping[str, Any] | None = None, scaling: bool = True,
               cse: bool = True, compile_flags: Sequence[str] | None = None,
               build_solver: bool = True, midpoint_bounds: bool = True,
               functions: tuple[tuple[PhaseFunction, ...], EndsFunction] | None = None
               ) -> Transcription:
    """Validate ``problem``, build its NLP and solver once, and return the transcription.

    Args:
        method: ``"hermite-simpson"`` (default; DIRCOL's compressed form),
            ``"hermite-simpson-separated"`` (the same scheme with the midpoint states as
            variables: same optimum, cheaper derivatives) or ``"trapezoidal"``.
        intervals: None (each phase's ``intervals``), an int for all phases, or by phase name
            an int (uniform) or an array of normalised knots in [0, 1].
        expand: evaluate the NLP as one SX graph rather than MX with mapped point functions.
            Default: True when not compiled (fastest interpreted), False when compiled (the
            generated C loops over the grid, so compiling takes seconds at any mesh size).
        compiled: None, ``"codegen"`` (C via gaitopt.codegen, cached on disk; recommended for
            repeated solves of one problem), ``"jit"`` (CasADi's jit, not cached) or
            ``"points"`` (separated Hermite-Simpson or trapezoidal without midpoint path
            constraints: exact derivatives assembled from compiled functions of one grid
            point, :mod:`gaitopt.ocp.pointwise`; the fastest where the dynamics are costly).
        options: solver options over the defaults (``{"ipopt.tol": 1e-10}`` or
            ``{"ipopt": {"tol": 1e-10}}``).
        scaling: scale variables and constraints from bounds or given scales.
        cse: eliminate common subexpressions in the point and ends functions.
        compile_flags: C compiler flags for ``compiled="codegen"`` (default
            ``gaitopt.codegen.DEFAULT_FLAGS``, ``-O2``; ``("-O1", "-fPIC", "-shared")``
            compiles faster).
        build_solver: build the solver for ``options`` now (default), or at the first solve
            (a caller that solves with a limited-memory Hessian first never derives the
            exact one it would not use: for a large expanded NLP, most of the build time).
        midpoint_bounds: separated Hermite-Simpson only: the state box bounds hold at the
            midpoint state variables too (default). ``False`` leaves them unbounded, which
            makes the NLP equivalent to the compressed one (the same optimum on every mesh).
        functions: the symbolic functions of ``problem`` from another transcription of it
            with the same ``scaling`` and ``cse`` (``other.functions``): they do not depend
            on the mesh or the method, and building them is most of a build.
    """
    if method not in METHODS:
        raise ProblemError(f"method must be one of {list(METHODS)}, got {method!r}")
    check_problem(problem)
    mesh = make_mesh(problem, intervals)
    return Transcription(problem, method, mesh, expand=expand, compiled=compiled,
                         options=options, scaling=scaling, cse=cse, compile_flags=compile_flags,
                         build_solver=build_solver, midpoint_bounds=midpoint_bounds,
                         functions=functions)
