"""Creating the IPOPT solver of an NLP (plain SX, MX, CasADi jit, or compiled C) and calling it.

Modes (``compiled``):

* ``None``: CasADi's virtual machine evaluates the functions (SX after ``expand`` by default).
* ``"codegen"``: the solver's five functions (``nlp_f, nlp_g, nlp_grad_f, nlp_jac_g,
  nlp_hess_l``) are generated as C, compiled with :mod:`gaitopt.codegen` into the on-disk
  cache, loaded back as external functions and passed to ``nlpsol`` through its
  Function-valued options ``grad_f``, ``jac_g``, ``hess_lag``. The library is keyed by a hash of
  the serialized NLP, so a second build of the same NLP skips deriving and compiling. With an
  MX NLP (the default when compiled) the C code loops over the mapped point functions, so its
  size and compile time do not grow with the mesh.
* ``"jit"``: CasADi's own just-in-time compilation (``jit=True``, shell compiler); compiled at
  every build, nothing cached.
* ``"points"``: the derivatives are assembled from compiled functions of one grid point
  (:mod:`gaitopt.ocp.pointwise`; :func:`solver_from_functions`), for transcriptions that
  evaluate the dynamics at single grid points (the separated Hermite-Simpson form).

A solve never raises: :func:`call_solver` returns the solution or an error message, except
for Ctrl-C, which it raises as :class:`KeyboardInterrupt`, and SIGTERM where
:func:`gaitopt.interrupts.terminate_as_interrupt` is installed, which it raises as
:class:`~gaitopt.interrupts.Terminated` (:func:`interrupt_watch`).
"""

from __future__ import annotations

import hashlib
import signal
import threading
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from gaitopt import codegen
from gaitopt.interrupts import raise_terminated

#: The solver options of every transcription. ``ipopt.mumps_mem_percent`` (IPOPT's default
#: 1000: MUMPS's working space eleven times its own estimate) at 100: on the seven-link
#: heel-toe walk an iteration took a quarter to a half less time with the smaller space, at
#: the same optima (a cold start without ankle torques at 72 m/min 43 -> 26 s, a warm step
#: 1.8 -> 1.1 s; docs/results/benchmarks-gait.md), and the five-link walk's small systems
#: the same time. Where MUMPS needs more, IPOPT doubles the percentage and factorizes again.
DEFAULT_OPTIONS: dict[str, Any] = {
    "ipopt.mumps_mem_percent": 100,
    "print_time": False,
    "record_time": True,
    "error_on_fail": False,
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-8,
    "ipopt.max_iter": 3000,
    "ipopt.linear_solver": "mumps",
}

COMPILED_MODES = (None, "codegen", "jit", "points")
EVAL_KINDS = ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l")


def exact_hessian(options: Mapping[str, Any]) -> bool:
    """Whether ``options`` ask IPOPT for the exact Hessian of the Lagrangian (the default)
    rather than a limited-memory quasi-Newton approximation, which needs no Hessian
    function: none is derived, which saves most of the build time of a large NLP."""
    return options.get("ipopt.hessian_approximation", "exact") != "limited-memory"


def derivative_kinds(options: Mapping[str, Any]) -> tuple[str, ...]:
    """The solver functions ``options`` need: all of :data:`EVAL_KINDS`, or all but
    ``nlp_hess_l`` with a limited-memory Hessian."""
    return EVAL_KINDS if exact_hessian(options) else EVAL_KINDS[:-1]


def merge_options(*layers: Mapping[str, Any] | None) -> dict[str, Any]:
    """Flatten nested ``{"ipopt": {...}}`` to ``"ipopt.key"`` and merge, later layers win."""
    out: dict[str, Any] = {}
    for layer in layers:
        for key, value in (layer or {}).items():
            if key == "ipopt" and isinstance(value, Mapping):
                for k, v in value.items():
                    out[f"ipopt.{k}"] = v
            else:
                out[key] = value
    return out


def options_key(options: Mapping[str, Any]) -> str:
    """A hashable key of an options dict (for caching solvers)."""
    return repr(sorted((k, repr(v)) for k, v in options.items()))


@dataclass(frozen=True)
class NlpFunctions:
    """The expanded (or MX) NLP as symbols ready for ``nlpsol``."""

    x: Any
    f: Any
    g: Any


def nlp_symbols(w_hat: ca.MX, f: ca.MX, g: ca.MX, expand: bool) -> NlpFunctions:
    """The NLP in SX (``expand``: faster evaluation) or left as MX."""
    if not expand:
        return NlpFunctions(w_hat, f, g)
    fn = ca.Function("nlp", [w_hat], [f, g]).expand()
    x = ca.SX.sym("w", w_hat.shape[0])
    f_sx, g_sx = fn(x)
    return NlpFunctions(x, f_sx, g_sx)


def _nlp_hash(nlp: NlpFunctions) -> str:
    fn = ca.Function("nlp", [nlp.x], [nlp.f, nlp.g])
    return hashlib.sha256(fn.serialize().encode()).hexdigest()[:16]


def _codegen_solver(name: str, nlp: NlpFunctions, options: dict[str, Any],
                    flags: tuple[str, ...]) -> ca.Function:
    kinds = derivative_kinds(options)
    digest = hashlib.sha256((_nlp_hash(nlp) + " ".join(flags) + " ".join(kinds)).encode()
                            ).hexdigest()[:16]
    lib_name = f"ocp_{digest}"
    cached = sorted(codegen.cache_dir().glob(f"{lib_name}-*.so"))
    if cached:
        path = cached[-1]
        codegen.mark_used(path)
    else:
        base = ca.nlpsol(f"{name}_base", "ipopt", {"x": nlp.x, "f": nlp.f, "g": nlp.g},
                         options)
        fns = [base.get_function(k) for k in kinds]
        path = codegen.compile_library(codegen.generate_source(fns, lib_name), lib_name,
                                       flags=flags)
    ext = {k: ca.external(k, str(path)) for k in kinds}
    X = ca.MX.sym("w", nlp.x.shape[0])
    P = ca.MX.sym("p", 0)
    opts = dict(options)
    opts.update(grad_f=ext["nlp_grad_f"], jac_g=ext["nlp_jac_g"], no_nlp_grad=True,
                calc_lam_p=False)
    if "nlp_hess_l" in ext:
        opts["hess_lag"] = ext["nlp_hess_l"]
    return ca.nlpsol(name, "ipopt", {"x": X, "f": ext["nlp_f"](X, P), "g": ext["nlp_g"](X, P)},
                     opts)


def make_solver(name: str, nlp: NlpFunctions, options: Mapping[str, Any],
                compiled: str | None,
                compile_flags: tuple[str, ...] = codegen.DEFAULT_FLAGS) -> ca.Function:
    """An IPOPT ``nlpsol`` for ``nlp`` in the requested evaluation mode.

    ``compile_flags`` are the C compiler flags of the ``"codegen"`` mode (they must produce a
    shared library: keep ``-fPIC -shared``).
    """
    opts = dict(options)
    if compiled is None:
        return ca.nlpsol(name, "ipopt", {"x": nlp.x, "f": nlp.f, "g": nlp.g}, opts)
    if compiled == "jit":
        opts.update(jit=True, compiler="shell", jit_cleanup=True,
                    jit_options={"flags": ["-O1", "-w"], "verbose": False})
        return ca.nlpsol(name, "ipopt", {"x": nlp.x, "f": nlp.f, "g": nlp.g}, opts)
    if compiled == "codegen":
        return _codegen_solver(name, nlp, opts, tuple(compile_flags))
    raise ValueError(f"compiled must be one of {COMPILED_MODES}, got {compiled!r}")


def solver_sharing_derivatives(name: str, base: ca.Function, n_w: int,
                               options: Mapping[str, Any]) -> ca.Function:
    """Another IPOPT solver of the same NLP as ``base`` with other ``options``.

    It takes ``base``'s objective, constraint, gradient, Jacobian and Hessian functions
    (``nlp_f``, ``nlp_g``, ``nlp_grad_f``, ``nlp_jac_g``, ``nlp_hess_l``) instead of deriving
    them again, which for a large expanded NLP costs seconds at the first call of every new
    solver. ``base`` must have the functions ``options`` need (:func:`derivative_kinds`): an
    exact-Hessian solver cannot share from a limited-memory one.
    """
    return solver_from_functions(name, {k: base.get_function(k) for k in EVAL_KINDS
                                        if k in derivative_kinds(options)}, n_w, options)


def solver_from_functions(name: str, functions: Mapping[str, ca.Function], n_w: int,
                          options: Mapping[str, Any]) -> ca.Function:
    """An IPOPT solver whose objective, constraints and derivatives are the given functions
    (by :data:`EVAL_KINDS` name, with nlpsol's signatures, e.g. ``nlp_jac_g: (x, p) -> (g,
    jac_g_x)``); ``nlp_hess_l`` is used only when ``options`` ask for the exact Hessian."""
    fns = {k: functions[k] for k in derivative_kinds(options)}
    x = ca.MX.sym("w", n_w)
    p = ca.MX.sym("p", 0)
    opts = dict(options)
    opts.update(grad_f=fns["nlp_grad_f"], jac_g=fns["nlp_jac_g"], no_nlp_grad=True,
                calc_lam_p=False)
    if "nlp_hess_l" in fns:
        opts["hess_lag"] = fns["nlp_hess_l"]
    return ca.nlpsol(name, "ipopt", {"x": x, "f": fns["nlp_f"](x, p), "g": fns["nlp_g"](x, p)},
                     opts)


@dataclass(frozen=True)
class SolverOutput:
    """What came back from one solver call (scaled vectors, as the solver saw them)."""

    x: np.ndarray
    lam_x: np.ndarray
    lam_g: np.ndarray
    f: float
    stats: dict[str, Any]
    error: str | None


#: The signals :func:`interrupt_watch` notes, each with the handler it must find installed
#: (else the process handles or ignores the signal itself, and keeps its handler); each such
#: handler raises a KeyboardInterrupt (:class:`~gaitopt.interrupts.Terminated` for SIGTERM).
WATCHED_SIGNALS: tuple[tuple[signal.Signals, Any], ...] = (
    (signal.SIGINT, signal.default_int_handler),
    (signal.SIGTERM, raise_terminated),
)


@contextmanager
def interrupt_watch() -> Iterator[Callable[[], type[KeyboardInterrupt] | None]]:
    """Watch for Ctrl-C (SIGINT), and for SIGTERM where
    :func:`gaitopt.interrupts.terminate_as_interrupt` is installed, during a solver call:
    yields a function that returns the exception to raise for the first such signal that came
    (KeyboardInterrupt, :class:`~gaitopt.interrupts.Terminated`), or None.

    CasADi checks for Ctrl-C between IPOPT's iterations, stops the solve and returns it as
    a failed one (status ``NonIpopt_Exception_Thrown``, the KeyboardInterrupt only logged as
    a warning), so a staged solve went on with its next stage and Ctrl-C never stopped it.
    Here each watched signal's handler is replaced, for the call, by one that notes the signal
    and raises as before (so IPOPT still stops at once); :func:`call_solver` then raises it.
    Only in the main thread, and only for a signal whose handler is the expected one
    (:data:`WATCHED_SIGNALS`)."""
    if threading.current_thread() is not threading.main_thread():
        yield lambda: None
        return
    seen: list[type[KeyboardInterrupt]] = []
    restore: list[tuple[signal.Signals, Any]] = []
    for signum, expected in WATCHED_SIGNALS:
        if signal.getsignal(signum) is not expected:
            continue

        def note(number: int, frame: Any, handler: Any = expected) -> None:
            try:
                handler(number, frame)
            except KeyboardInterrupt as exc:
                seen.append(type(exc))
                raise

        signal.signal(signum, note)
        restore.append((signum, expected))
    try:
        yield lambda: seen[0] if seen else None
    finally:
        for signum, handler in restore:
            signal.signal(signum, handler)


def call_solver(solver: ca.Function, args: dict[str, Any]) -> SolverOutput:
    """Run ``solver(**args)``; any exception becomes ``error`` (with x = x0).

    Raises:
        KeyboardInterrupt: Ctrl-C during the call, or :class:`~gaitopt.interrupts.Terminated`
            for SIGTERM where :func:`~gaitopt.interrupts.terminate_as_interrupt` is installed
            (:func:`interrupt_watch`).
    """
    with interrupt_watch() as interrupted:
        try:
            sol = solver(**args)
            error = None
        except Exception as exc:  # noqa: BLE001 - the solver may raise anything; report it
            sol = None
            error = (f"{type(exc).__name__}: "
                     f"{str(exc).strip().splitlines()[-1] if str(exc) else ''}")
    if (stop := interrupted()) is not None:
        raise stop
    try:
        stats = dict(solver.stats())
    except Exception:  # noqa: BLE001
        stats = {}
    if sol is None:
        x0 = np.asarray(args["x0"], dtype=float).ravel()
        ng = np.asarray(args["lbg"]).size
        return SolverOutput(x0, np.zeros_like(x0), np.zeros(ng), float("nan"), stats, error)
    return SolverOutput(np.asarray(sol["x"], dtype=float).ravel(),
                        np.asarray(sol["lam_x"], dtype=float).ravel(),
                        np.asarray(sol["lam_g"], dtype=float).ravel(),
                        float(sol["f"]), stats, None)
