"""Exact NLP derivatives assembled from derivatives at single grid points (compiled once).

In a transcription whose constraints touch the dynamics at single grid points only (separated
Hermite-Simpson; trapezoidal without midpoint path constraints) the scaled NLP has the form::

    f(w) = F(w, Y),   g(w) = G(w, Y),   Y_j = phi(z_j(w))   at every point j,

where ``phi(z) -> y`` is a point function of one point: the phase's
``(x, u, p, t) -> (xdot (n), path (r), L (1))`` at its midpoints and first knot, the same with
the phase's knot states computed inside and returned as a fourth output at its other knots
(:func:`gaitopt.ocp.functions.knot_point`), and the constraint rows of the ends function
(linkages, boundary; one call). ``z_j`` is its input (a selection of w and the time, a cheap
expression of w), and ``F``, ``G`` (the "outer" functions: defects, quadrature, the
objective's end terms, scaling) are cheap expressions, affine in ``Y`` apart from the
durations. With ``J = blockdiag_j dphi/dz (z_j)`` (ny x nz per point), ``Dz = dz/dw``, the
Lagrangian ``L = sigma F + lambda^T G``, ``mu = dL/dY = G_Y^T lambda + sigma F_Y`` (ny per
point), ``nu = J^T mu`` and ``H = blockdiag_j Hess_z (mu_j^T phi)(z_j)`` (nz x nz per point),
the chain rule gives::

    grad f  = F_w + Dz^T J^T F_Y                                          (nw,)
    jac g   = G_w + G_Y J Dz                                              (ng, nw)
    hess L  = L_ww + (L_wY J Dz) + (L_wY J Dz)^T + (J Dz)^T L_YY (J Dz)
              + Dz^T H Dz + Hess_w (nu^T z(w))                            (nw, nw)

(IPOPT receives the upper triangle; the last term is derived only where ``z(w)`` is not
affine, e.g. with durations that are products of parameters). ``g`` is ``G`` of the mapped
point values; ``f`` and ``grad f`` are one SX graph with the point outputs ``f`` reads (the
cheap integrand) inlined at every point. Only ``phi``, its Jacobian and the weighted Hessian
``Hess_z (mu^T phi)`` see the dynamics, the event maps and the knot states; they are
functions of one point, so their size and the time to compile them do not depend on the
mesh. They are generated as C once per point function and compiled into the disk cache of
:mod:`gaitopt.codegen` (keyed by a hash of the serialized point function, which determines
the C, see :func:`library_key`: a changed model or problem compiles anew; an unchanged one
loads in milliseconds) and mapped over the grid. Without a C compiler the same functions run
in CasADi's virtual machine.

The outer functions are SX functions, always interpreted, and they are not derived for every
mesh either: the terms of each interval (defects, midpoint defects, the quadrature of the
integrand and the control-rate term) are recorded like the point outputs, as symbols ``R =
r(v)`` of one interval's inputs ``v`` (a selection of w and of the point outputs, one column
per interval), and the function ``r`` of one interval (:func:`interval_template`: a function
of the phase's sizes, the method and the forms of the cost and the duration, not of the mesh)
is derived once per process (:func:`interval_derivatives`) and mapped over the intervals.
What remains of ``F, G`` is affine in ``Y`` and ``R`` apart from the ends' objective terms
and the duration rows: its rows that select one entry (the interval terms, the path
constraints, the linkages and boundary conditions, scaled) have a constant Jacobian, read off
by evaluating them, and only the few others are differentiated for each mesh (see
``_Outer``; ``docs/results/benchmarks-gait.md``, "Build time independent of the mesh").
"""

from __future__ import annotations

import hashlib
import logging
import time
import warnings
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from gaitopt import codegen
from gaitopt.ocp.functions import IdentityCache
from gaitopt.ocp.method import Method
from gaitopt.ocp.nlp import Assembly, IntervalInputs, interval_terms

#: C compiler flags of the point libraries: ``-O1`` compiles the five-link biped's point
#: Hessians about twice as fast as ``-O2`` (3-6 s against 4-13 s per phase on an idle
#: machine).
POINT_FLAGS: tuple[str, ...] = ("-O1", "-fPIC", "-shared")
#: Flags for large point functions (more than :data:`LARGE_POINT` instructions, e.g. the
#: seven-link model with feet), whose C is split into chunk functions first
#: (:func:`gaitopt.codegen.split_straight_line`): one C function of 30,000 statements takes
#: GCC's register allocation most of an optimizing compile. The seven-link's heel-off library
#: (Jacobian and Hessian of a point): ``-Og`` in chunks 2.5 s to compile and 12.7 us per
#: point Hessian, against ``-O0`` whole 1.3 s and 36 us, ``-O1`` whole 8.8 s and 11.6 us
#: (docs/results/benchmarks-gait.md, "Point libraries in chunks").
LARGE_POINT_FLAGS: tuple[str, ...] = ("-Og", "-fPIC", "-shared")
LARGE_POINT = 1300


def point_flags(point: ca.Function) -> tuple[str, ...]:
    """The compiler flags of ``point``'s library (by its number of instructions)."""
    return POINT_FLAGS if point.n_instructions() <= LARGE_POINT else LARGE_POINT_FLAGS


#: The interval templates serve meshes of at least this many intervals (all phases): below,
#: deriving the outer functions of the mesh is as cheap as building from the templates, and
#: the templates' fixed cost per evaluation (more nodes and calls) outweighs it over a coarse
#: stage's iterations (the five-link walk at 8 + 5 knots: the same build, ``nlp_hess_l``
#: 0.71 against 0.43 ms; at 16 + 6: the same evaluations; at 40 + 10 and beyond builds 0.6-0.8
#: of the derived ones; ``docs/results/benchmarks-gait.md``).
TEMPLATE_MIN_INTERVALS = 24
#: Says when point libraries are compiled (the first solve of a model and problem on a
#: machine waits for it: the seven-link biped's nine libraries about 34 s on two cores); the
#: ``gaitopt`` command shows its INFO records on stderr (:func:`gaitopt.cli.main`).
LOG = logging.getLogger(__name__)
#: Version of the generated point libraries (part of their cache key): change it when the
#: functions a library holds, or their C (:data:`gaitopt.codegen.CHUNK_STATEMENTS`), change.
FORMAT = "gaitopt-points-2"


def supports(method: Method, has_midpoint_rows: bool) -> bool:
    """Whether the NLP of ``method`` evaluates the dynamics at single grid points only (no
    point function of an expression of point outputs): the separated Hermite-Simpson form,
    or a method without midpoint dynamics and without path constraints at midpoints."""
    if method.midpoint_variables:
        return True
    return not (method.needs_midpoint_dynamics or has_midpoint_rows)


def stacked_point(point: ca.Function) -> ca.Function:
    """``point(x, u, p, t) -> (xdot, path, L)`` as one function of ``z = [x; u; p; t]``
    (nz, 1) returning ``y = [xdot; path; L]`` (ny, 1)."""
    sizes = [point.size1_in(i) for i in range(point.n_in())]
    z = ca.SX.sym("z", int(sum(sizes)))
    parts = ca.vertsplit(z, np.concatenate([[0], np.cumsum(sizes)]).astype(int).tolist())
    y = ca.vertcat(*point(*parts))
    return ca.Function(stacked_name(point), [z], [y], ["z"], ["y"])


def stacked_name(point: ca.Function) -> str:
    """The name of :func:`stacked_point` of ``point`` (its derivatives add ``_jac``,
    ``_hess``)."""
    return f"{point.name()}_y"


@dataclass(frozen=True)
class PointDerivatives:
    """The functions of one point: ``value(z) -> y``, ``jacobian(z) -> (y, J)`` with J
    (ny, nz), ``hessian(z, mu) -> (J, H)`` with H = Hess_z (mu^T y) (nz, nz), symmetric.
    ``compiled``: loaded from a C library (else CasADi SX functions)."""

    value: ca.Function
    jacobian: ca.Function
    hessian: ca.Function
    compiled: bool

    @staticmethod
    def of(functions: list[ca.Function], compiled: bool) -> PointDerivatives:
        """From ``[value, jacobian, hessian]``."""
        value, jacobian, hessian = functions
        return PointDerivatives(value, jacobian, hessian, compiled)

    @staticmethod
    def derive(point: ca.Function) -> list[ca.Function]:
        """The three SX functions of ``point`` (see the class docstring)."""
        phi = stacked_point(point)
        z = ca.SX.sym("z", phi.size1_in(0))
        y = phi(z)
        mu = ca.SX.sym("mu", y.shape[0])
        jac = ca.jacobian(y, z)
        hess, _ = ca.hessian(ca.dot(mu, y), z)
        base = phi.name()
        return [phi,
                ca.Function(f"{base}_jac", [z], list(ca.cse([y, jac])), ["z"], ["y", "J"]),
                ca.Function(f"{base}_hess", [z, mu], list(ca.cse([jac, hess])), ["z", "mu"],
                            ["J", "H"])]


#: :func:`library_key` by the point function (the transcriptions of one problem on other
#: meshes call the same point functions: they are serialized and hashed once).
_KEYS = IdentityCache(32)


def library_key(point: ca.Function, flags: tuple[str, ...] = POINT_FLAGS) -> str:
    """The cache key of the point library of ``point``: a hash of the serialized point
    function, CasADi's version, the compiler and its flags, :data:`FORMAT` and the chunk size
    of :func:`~gaitopt.codegen.split_straight_line` (the C is a
    deterministic function of these, so a cached library is found without deriving or
    generating anything)."""
    def make() -> str:
        text = "\0".join([FORMAT, str(codegen.CHUNK_STATEMENTS), point.serialize(),
                          ca.CasadiMeta.version(), codegen.compiler(), *flags])
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    return _KEYS.get((point, codegen.compiler(), *flags), make)


def point_source(point: ca.Function, lib: str, flags: tuple[str, ...]) -> str:
    """The C of library ``lib`` of ``point`` (:meth:`PointDerivatives.derive`), split into
    chunk functions (:func:`gaitopt.codegen.split_straight_line`) when compiled with
    :data:`LARGE_POINT_FLAGS`."""
    source = codegen.generate_source(PointDerivatives.derive(point), lib)
    return codegen.split_straight_line(source) if flags == LARGE_POINT_FLAGS else source


def point_derivatives(points: list[ca.Function], compile_c: bool
                      ) -> list[PointDerivatives]:
    """The :class:`PointDerivatives` of each point function; with ``compile_c`` compiled
    (one library per point function, compiled in parallel, cached on disk by
    :func:`library_key`), else, or when no C compiler is found or it fails (a warning),
    CasADi SX functions."""
    if not (compile_c and codegen.has_compiler()):
        return [PointDerivatives.of(PointDerivatives.derive(p), compiled=False) for p in points]
    libs = {f"pt_{p.name()}": p for p in points}
    flags = {lib: point_flags(p) for lib, p in libs.items()}
    paths = {lib: codegen.cache_dir() / f"{lib}-{library_key(p, flags[lib])}.so"
             for lib, p in libs.items()}
    missing = [lib for lib, path in paths.items() if not path.exists()]
    for lib, path in paths.items():
        if lib not in missing:
            codegen.mark_used(path)
    if missing:
        LOG.info("compiling %d point %s of this model and problem into %s (once per "
                 "machine) ...", len(missing), "library" if len(missing) == 1 else "libraries",
                 codegen.cache_dir())
        start = time.perf_counter()
        sources = {lib: point_source(libs[lib], lib, flags[lib]) for lib in missing}
        try:
            codegen.compile_libraries(sources, targets={lib: paths[lib] for lib in missing},
                                      flags_by_name={lib: flags[lib] for lib in missing})
            LOG.info("compiled in %.1f s", time.perf_counter() - start)
        except codegen.CompileError as exc:
            warnings.warn(f"compiling the point functions failed, evaluating them in CasADi's "
                          f"VM instead: {str(exc)[:300]}", RuntimeWarning, stacklevel=2)
            return point_derivatives(points, compile_c=False)
    out = []
    for lib, p in libs.items():
        base = stacked_name(p)
        ext = [ca.external(name, str(paths[lib]))
               for name in (base, f"{base}_jac", f"{base}_hess")]
        out.append(PointDerivatives.of(ext, compiled=True))
    return out


@dataclass(frozen=True)
class _Group:
    """The M calls of one point function: their inputs z (nz, M) as an SX expression of w
    and the symbols standing for their outputs (ny, M)."""

    point: ca.Function
    z: ca.SX
    y: ca.SX


#: The constraint rows of an ends function (:meth:`PointRecorder.ends`), by the function.
_ROWS = IdentityCache(8)


@dataclass(frozen=True)
class _IntervalGroup:
    """The N intervals of one phase: the function of one interval, its inputs v (nv, N) as
    an SX expression of w and of the point outputs, the normalised interval lengths dtau
    (1, N) and the symbols standing for its outputs (nr, N)."""

    template: ca.Function
    v: ca.SX
    dtau: ca.DM
    r: ca.SX


class PointRecorder:
    """A :data:`gaitopt.ocp.nlp.PointCalls` that records the inputs of every point call
    (SX) and returns fresh symbols for the outputs; :meth:`ends` does the same for the ends
    function (:data:`gaitopt.ocp.nlp.EndsCall`), a point function called once."""

    def __init__(self) -> None:
        self.groups: list[_Group] = []
        self.interval_groups: list[_IntervalGroup] = []

    def _record(self, point: ca.Function, z: ca.SX) -> list[ca.SX]:
        """Record the calls of ``point`` on the columns of ``z`` (its inputs stacked); its
        outputs (each a column) as symbols, one column per call."""
        sizes = [point.size1_out(j) for j in range(point.n_out())]
        y = ca.SX.sym(f"y{len(self.groups)}", int(sum(sizes)), int(z.shape[1]))
        self.groups.append(_Group(point, z, y))
        bounds = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
        return [y[int(a):int(b), :] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]

    def __call__(self, i: int, point: ca.Function, X: Any, U: Any, p: Any, t: Any
                 ) -> tuple[Any, ...]:
        M = int(X.shape[1])
        return tuple(self._record(point, ca.vertcat(X, U, ca.repmat(p, 1, M), t)))

    def ends(self, fn: ca.Function, E: Any, p: Any) -> list[Any]:
        """The ends function's constraint rows (linkages, boundary) as symbols: their
        derivatives, of one call, are then derived and compiled once per problem like those
        of the phases' point functions, instead of for every mesh (their Hessian, with the
        event maps, was the largest part of the outer one). The objective's terms (Mayer,
        parameter cost, denominator) stay in the outer functions, which keeps the objective
        affine in the recorded outputs (a ratio of recorded outputs has a dense Hessian
        row)."""
        z = ca.vertcat(E, p)

        def make() -> ca.Function:
            E_sym = ca.SX.sym("E", fn.size1_in(0))
            p_sym = ca.SX.sym("p", fn.size1_in(1))
            return ca.Function(f"{fn.name()}_rows", [E_sym, p_sym],
                               fn.call([E_sym, p_sym])[:2], ["E", "p"],
                               ["linkages", "boundary"])

        link, bnd = self._record(_ROWS.get((fn,), make), z)
        return [link, bnd, *fn.call([E, p])[2:]]


    def intervals(self, i: int, inp: IntervalInputs) -> tuple[Any, Any, Any]:
        """Record the terms of the phase's intervals (:data:`gaitopt.ocp.nlp.IntervalCalls`):
        their inputs (a selection of w and of the point outputs, one column per interval) and
        symbols for their outputs (defects, midpoint defects, quadrature); the function of
        one interval is :func:`interval_template`."""
        n, N = int(inp.x_k.shape[0]), int(inp.x_k.shape[1])
        template = interval_template(inp)
        controls = (inp.u_k, inp.u_k1) if inp.rates is not None else (None, None)
        v = ca.vertcat(*[c for c in (inp.x_k, inp.x_k1, inp.xm, inp.f_k, inp.f_k1, inp.f_m,
                                     inp.l_k, inp.l_k1, inp.l_m, *controls) if c is not None],
                       ca.repmat(inp.t_source, 1, N))
        assert v.shape == (template.size1_in(0), N), (v.shape, template.size_in(0))
        nr = template.size1_out(0)
        r = ca.SX.sym(f"r{len(self.interval_groups)}", nr, N)
        self.interval_groups.append(_IntervalGroup(template, v, inp.dtau, r))
        return r[:n, :], (None if inp.xm is None else r[n:2 * n, :]), r[nr - 1:, :]


def interval_template(inp: IntervalInputs) -> ca.Function:
    """The terms of one interval of ``inp`` (:func:`gaitopt.ocp.nlp.interval_terms`) as a
    function ``(v, dtau) -> [defects; midpoint defects; cost]`` of one column ``v = [x_k;
    x_k1; xm; f_k; f_k1; f_m; l_k; l_k1; l_m; u_k; u_k1; t_source]`` (the parts the method
    and the cost have; the control-rate weights are constants of the template) and the
    normalised interval length: a function of the phase's sizes, the method, the cost's
    form and the duration's form only, the same on every mesh."""
    n, s = int(inp.x_k.shape[0]), int(inp.t_source.shape[0])
    mid = inp.f_m is not None
    names = ["x_k", "x_k1", *(["xm"] if inp.xm is not None else []), "f_k", "f_k1",
             *(["f_m"] if mid else [])]
    parts = {name: ca.SX.sym(name, n) for name in names}
    parts |= {name: ca.SX.sym(name) for name in ("l_k", "l_k1", *(["l_m"] if mid else []))}
    if inp.rates is not None:
        m = int(inp.rates.shape[0])
        parts |= {name: ca.SX.sym(name, m) for name in ("u_k", "u_k1")}
    t_source, dtau = ca.SX.sym("t", s), ca.SX.sym("dtau")
    local = IntervalInputs(inp.method, parts["x_k"], parts["x_k1"], parts.get("xm"),
                           parts["f_k"], parts["f_k1"], parts.get("f_m"), parts["l_k"],
                           parts["l_k1"], parts.get("l_m"), None, ca.DM(), t_source, inp.t_of,
                           parts.get("u_k"), parts.get("u_k1"), inp.rates)
    defects, mid_defects, quadrature = interval_terms(local, inp.t_of(t_source), dtau)
    out = ca.vertcat(defects, *([] if mid_defects is None else [mid_defects]), quadrature)
    v = ca.vertcat(*parts.values(), t_source)
    return ca.Function("interval", [v, dtau], [out], ["v", "dtau"], ["r"])


@dataclass(frozen=True)
class IntervalDerivatives:
    """The derivatives of an :func:`interval_template` ``r(v, dtau)``: ``jacobian(v, dtau)
    -> (r, dr/dv)`` and ``hessian(v, dtau, mu) -> (dc/dv, (dr/dv)^T mu, Hess_v (mu^T r))``
    with ``c`` the interval's cost (the last row of r: the objective's second derivatives
    couple it to the ends' terms) (SX functions, evaluated in CasADi's VM)."""

    value: ca.Function
    jacobian: ca.Function
    hessian: ca.Function


#: The derivatives of every interval template derived in this process, by a hash of the
#: serialized template: a template is derived once, whatever the mesh.
_INTERVAL_DERIVATIVES: OrderedDict[str, IntervalDerivatives] = OrderedDict()
#: How many derived templates :data:`_INTERVAL_DERIVATIVES` keeps (the newest).
INTERVAL_CACHE_SIZE = 64
#: How many interval templates this process has derived (a test checks that a second mesh
#: of a problem derives none).
interval_derivations = 0


def interval_derivatives(template: ca.Function) -> IntervalDerivatives:
    """The (process-wide cached) :class:`IntervalDerivatives` of ``template``."""
    global interval_derivations
    key = hashlib.sha256(template.serialize().encode()).hexdigest()
    if key not in _INTERVAL_DERIVATIVES:
        v, dtau = ca.SX.sym("v", template.size1_in(0)), ca.SX.sym("dtau")
        r = template(v, dtau)
        mu = ca.SX.sym("mu", r.shape[0])
        jac = ca.jacobian(r, v)
        hess, grad = ca.hessian(ca.dot(mu, r), v)
        _INTERVAL_DERIVATIVES[key] = IntervalDerivatives(
            template,
            ca.Function("interval_jac", [v, dtau], list(ca.cse([r, jac])), ["v", "dtau"],
                        ["r", "J"]),
            ca.Function("interval_hess", [v, dtau, mu],
                        list(ca.cse([jac[jac.shape[0] - 1, :], grad, hess])),
                        ["v", "dtau", "mu"], ["J", "g", "H"]))
        interval_derivations += 1
        while len(_INTERVAL_DERIVATIVES) > INTERVAL_CACHE_SIZE:
            _INTERVAL_DERIVATIVES.popitem(last=False)
    _INTERVAL_DERIVATIVES.move_to_end(key)
    return _INTERVAL_DERIVATIVES[key]


def _block_diagonal(mapped: ca.MX, block: ca.Sparsity, count: int) -> ca.MX:
    """The block-diagonal matrix of ``count`` blocks of sparsity ``block`` from their
    horizontal concatenation ``mapped`` (a map's output): both store the nonzeros in the same
    (column-major) order."""
    sp = ca.diagcat(*[ca.DM(block, 1.0)] * count).sparsity()
    return ca.MX(sp, mapped.nz[:])


def _inlined_outputs(expr: ca.SX, groups: list[_Group]) -> tuple[ca.SX, ca.SX]:
    """The point-output symbols ``expr`` reads and their values as SX expressions of w (the
    point functions inlined, pruned to those outputs): the arguments of ``ca.substitute``
    that make ``expr`` an expression of w alone."""
    Y = ca.vertcat(*[ca.vec(gr.y) for gr in groups])
    read = set(ca.jacobian_sparsity(expr, Y).get_col())
    symbols, values = [], []
    pos = 0
    for gr in groups:
        ny, M = int(gr.y.shape[0]), int(gr.z.shape[1])
        rows = sorted({(j - pos) % ny for j in read if pos <= j < pos + ny * M})
        pos += ny * M
        if not rows:
            continue
        z = ca.SX.sym("z", gr.z.shape[0])
        pruned = ca.Function("outputs", [z], [stacked_point(gr.point)(z)[rows]])
        symbols.append(ca.vec(gr.y[rows, :]))
        values.append(ca.vec(pruned.map(M)(gr.z)))
    if not symbols:
        return ca.SX(0, 1), ca.SX(0, 1)
    return ca.vertcat(*symbols), ca.densify(ca.vertcat(*values))


@dataclass(frozen=True)
class PointwiseNlp:
    """The solver functions of an NLP with the signatures ``nlpsol`` uses:
    ``nlp_f (w, p) -> f``, ``nlp_g (w, p) -> g``, ``nlp_grad_f (w, p) -> (f, grad)``,
    ``nlp_jac_g (w, p) -> (g, jac)``, ``nlp_hess_l (w, p, lam_f, lam_g) -> triu(hess)``."""

    functions: dict[str, ca.Function]
    compiled: bool
    #: The point functions whose derivatives the NLP's are assembled from (one per group).
    point_functions: tuple[ca.Function, ...] = ()
    #: Each point function with its own signature, evaluated through its library's value
    #: function where compiled (:func:`unstacked_value`; else the point function itself).
    point_evaluators: tuple[ca.Function, ...] = ()

    def evaluator(self, point: ca.Function) -> ca.Function:
        """``point`` (one of :attr:`point_functions`) as :attr:`point_evaluators` has it;
        ``point`` itself for any other function."""
        for f, ev in zip(self.point_functions, self.point_evaluators, strict=True):
            if f is point:
                return ev
        return point


def _selections(v: ca.SX, u: ca.SX) -> tuple[ca.DM, list[int]]:
    """The rows of ``v`` that are a constant times one entry of ``u`` as a constant matrix S
    (``v[r] = S[r, :] u`` on those rows, zero rows elsewhere), found by evaluating ``v``
    instead of differentiating it, and the other rows."""
    f = ca.Function("v", [u], [v])
    nv, nu = int(v.shape[0]), int(u.shape[0])
    rng = np.random.default_rng(0)
    probes = [np.zeros(nu), np.ones(nu), np.arange(1.0, nu + 1.0), rng.uniform(1, 2, nu),
              rng.uniform(-2, -1, nu)]
    zero, one, index, *checks = (np.asarray(f(x), dtype=float).ravel() for x in probes)
    with np.errstate(divide="ignore", invalid="ignore"):
        col = index / one - 1.0
        ok = (zero == 0.0) & (one != 0.0) & np.isfinite(col)
        ok &= np.abs(np.where(ok, col - np.round(col), 1.0)) < 1e-6
    col = np.where(ok, np.round(col), 0).astype(int)
    ok &= (col >= 0) & (col < nu)
    col = np.where(ok, col, 0)  # a product u_i u_j gives an integer "column" beyond nu
    for x, value in zip(probes[3:], checks, strict=True):
        ok &= np.abs(one * x[col] - value) <= 1e-12 * np.maximum(1.0, np.abs(value))
    rows = np.flatnonzero(ok)
    S = ca.DM.triplet(rows.tolist(), col[rows].tolist(), one[rows].tolist(), nv, nu)
    return S, [int(r) for r in np.flatnonzero(~ok)]


def _linear_jacobian(v: ca.SX, u: ca.SX) -> ca.SX:
    """``jacobian(v, u)``, with the rows that select one entry of u (``_selections``)
    read off by evaluation and only the others differentiated."""
    S, rest = _selections(v, u)
    if not rest:
        return ca.SX(S)
    place = ca.DM.triplet(rest, list(range(len(rest))), [1.0] * len(rest), int(v.shape[0]),
                          len(rest))
    return ca.SX(S) + ca.mtimes(place, ca.jacobian(v[rest], u))


def _selection(v: ca.SX, u: ca.SX) -> ca.DM:
    """The constant matrix S with ``v = S u`` for ``v`` linear in ``u`` (each entry a
    constant times one entry of u, else by the Jacobian of the other rows)."""
    S, other = _selections(v, u)
    if not other:
        return S
    rest = ca.evalf(ca.jacobian(v[other], u))
    place = ca.DM.triplet(other, list(range(len(other))), [1.0] * len(other),
                          int(v.shape[0]), len(other))
    return S + ca.mtimes(place, rest)


class _Scatter:
    """``C1 B C2`` for constant selections C1, C2 (at most one entry per column of C1 and
    per row of C2) and a matrix B of a given sparsity, as a constant sparse matrix M taking
    B's nonzeros to the product's (a nonzero of B at (r, c) contributes ``C1[i, r] C2[c, j]``
    to entry (i, j); contributions to one entry add up), built with numpy from the sparsity
    patterns: evaluating it is one sparse matrix-vector product, nothing is derived."""

    def __init__(self, C1: ca.DM, block: ca.Sparsity, C2: ca.DM) -> None:
        C1, C2 = ca.DM(C1), ca.DM(C2)
        rows, cols = (np.asarray(a, dtype=int) for a in block.get_triplet())
        c1_rows, c1_cols = (np.asarray(a, dtype=int) for a in C1.sparsity().get_triplet())
        c2_rows, c2_cols = (np.asarray(a, dtype=int) for a in C2.sparsity().get_triplet())
        c1_vals = np.asarray(C1.nonzeros(), dtype=float)
        c2_vals = np.asarray(C2.nonzeros(), dtype=float)
        if (np.bincount(c1_cols, minlength=1).max(initial=0) > 1
                or np.bincount(c2_rows, minlength=1).max(initial=0) > 1):
            # Not selections: C1 B C2 of a symbolic B, and the map read off its Jacobian.
            b = ca.SX.sym("b", block.nnz())
            prod = ca.mtimes([ca.SX(C1), ca.SX(block, b), ca.SX(C2)])
            self.sparsity = prod.sparsity()
            values = ca.reshape(prod[prod.sparsity()], prod.nnz(), 1)
            self.matrix = ca.evalf(ca.jacobian(values, b))
            return
        # Selections: each nonzero of B goes to at most one entry of the product.
        to_i = np.full(int(C1.shape[1]), -1)
        to_a = np.zeros(int(C1.shape[1]))
        to_i[c1_cols], to_a[c1_cols] = c1_rows, c1_vals
        to_j = np.full(int(C2.shape[0]), -1)
        to_b = np.zeros(int(C2.shape[0]))
        to_j[c2_rows], to_b[c2_rows] = c2_cols, c2_vals
        out_i, out_j = to_i[rows], to_j[cols]
        keep = np.flatnonzero((out_i >= 0) & (out_j >= 0))
        coef = to_a[rows[keep]] * to_b[cols[keep]]
        self.sparsity, mapping = ca.Sparsity.triplet(
            int(C1.shape[0]), int(C2.shape[1]), out_i[keep].tolist(), out_j[keep].tolist(),
            True)
        self.matrix = ca.DM.triplet(list(mapping), keep.tolist(), coef.tolist(),
                                    self.sparsity.nnz(), block.nnz())

    def __call__(self, nz: ca.MX) -> ca.MX:
        """The product for B with nonzeros ``nz``."""
        return ca.MX(self.sparsity, ca.mtimes(self.matrix, nz))


class _Outer:
    """The outer functions of the SX ``assembly`` (defects, quadrature, linkages, scaling)
    and their derivatives with respect to w and the point outputs Y, as MX functions of
    ``(W, Y)``: :meth:`g` (G), :meth:`jacobian` (G, G_w, G_Y) and :meth:`hessian` (L_ww,
    L_wY, L_YY, L_Y = mu) of ``L = sigma F + lambda^T G``.

    The terms of the intervals (defects, midpoint defects, quadrature: ``R``, recorded as
    symbols, ``R = r(v(w, Y))`` with ``v = S [w; Y]`` a selection) come from the interval
    templates, derived once per template (:func:`interval_derivatives`) and mapped over the
    intervals; what remains, ``F(w, Y, R)`` and ``G(w, Y, R)``, is affine in Y and R apart
    from the ends' objective terms (Mayer, parameter cost, denominator) and the duration
    rows: its rows that select one entry of ``(w, Y, R)`` have a constant Jacobian, read off by
    evaluation (``_selections``), and only the other rows and ``F`` are differentiated
    for each mesh (a few expressions of the ends and the parameters). With ``A =
    blockdiag(dr/dv) S`` and the residual Lagrangian ``L0(u, R)``, ``u = [w; Y]``::

        G_u  = G0_u + G0_R A
        L_u  = L0_u + S^T (dr/dv)^T L0_R
        L_uu = L0_uu + L0_uR A + (L0_uR A)^T + A^T L0_RR A + S^T blockdiag(Hess_v(mu_R^T r)) S

    The products are SX functions of the nonzeros of the mapped interval derivatives
    (sparse products of constant selections: built for each mesh, not derived).
    """

    def __init__(self, assembly: Assembly, Y: ca.SX, intervals: list[_IntervalGroup]
                 ) -> None:
        w = assembly.w_hat
        self.nw, self.ny = int(w.shape[0]), int(Y.shape[0])
        ng = int(assembly.g.shape[0])
        self.intervals = [ig for ig in intervals if ig.r.shape[1] > 0]
        R = ca.vertcat(*[ca.vec(ig.r) for ig in self.intervals]) if self.intervals else \
            ca.SX(0, 1)
        self.derivs = [interval_derivatives(ig.template) for ig in self.intervals]
        F, G = assembly.f, assembly.g
        sigma, lam = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", ng)
        # Most rows of G are a scale times one entry of (w, Y, R) (the interval terms, path
        # constraints, linkages, boundary conditions): their Jacobian is a constant matrix,
        # read off by evaluation; only the other rows (durations, ...) are differentiated,
        # and only they and F enter the second derivatives.
        u = ca.vertcat(w, Y, R)
        S_G, rest = _selections(G, u)
        G_rest = G[rest]
        J_rest = ca.jacobian(G_rest, u)
        place = ca.DM.triplet(rest, list(range(len(rest))), [1.0] * len(rest), ng, len(rest))
        G_u = ca.SX(S_G) + ca.mtimes(place, J_rest) if rest else ca.SX(S_G)
        nw, ny = self.nw, self.ny
        G_w, G_Y, G_R = G_u[:, :nw], G_u[:, nw:nw + ny], G_u[:, nw + ny:]
        # g with the interval terms inlined (their values are small functions): one VM pass.
        self._g = ca.Function("outer_g", [w, Y], [self._inlined(G, R)])
        # mu = L_Y from G_Y (sparse, G is affine in Y for collocation) rather than by reverse
        # AD of the whole Lagrangian, and L_wY as the transpose of d(mu)/dw: mu depends on few
        # entries of w (durations, parameters), where the Jacobian of the large gradient graph
        # L_w with respect to Y took 4x as long (60 + 15 knots, full coordinates: 0.014 s
        # against 0.061 s). The same for R.
        F_Y, F_R = ca.gradient(F, Y), ca.gradient(F, R)
        L_Y = ca.mtimes(G_Y.T, lam) + sigma * F_Y
        L_R = ca.mtimes(G_R.T, lam) + sigma * F_R
        lam_rest = lam[rest]
        curved = sigma * F + ca.dot(lam_rest, G_rest)
        J_rest_Y, J_rest_R = J_rest[:, nw:nw + ny], J_rest[:, nw + ny:]
        L_Y2 = ca.mtimes(J_rest_Y.T, lam_rest) + sigma * F_Y
        L_R2 = ca.mtimes(J_rest_R.T, lam_rest) + sigma * F_R
        L_ww = ca.hessian(curved, w)[0]
        L_wY, L_YY = ca.jacobian(L_Y2, w).T, ca.jacobian(L_Y2, Y)
        L_wR, L_YR, L_RR = ca.jacobian(L_R2, w).T, ca.jacobian(L_R2, Y).T, ca.jacobian(L_R2, R)
        if not self.intervals:
            self._jac = ca.Function("outer_jac", [w, Y, R], [G, G_w, G_Y])
            self._hess = ca.Function("outer_hess", [w, Y, R, sigma, lam],
                                     [L_ww, L_wY, L_YY, L_Y])
            return
        self._mu = ca.Function("outer_mu", [w, Y, R, sigma, lam], [L_R])
        V = ca.vertcat(*[ca.vec(ig.v) for ig in self.intervals])
        S = _selection(V, ca.vertcat(w, Y))
        self.S = S
        rows, cols = (np.asarray(a, dtype=int) for a in S.sparsity().get_triplet())
        self._pick: tuple[list[int], ca.DM] | None = None
        if rows.size == S.shape[0] and np.array_equal(np.sort(rows), np.arange(rows.size)):
            order = np.argsort(rows)
            self._pick = (cols[order].tolist(),
                          ca.DM(np.asarray(S.nonzeros(), dtype=float)[order]))
        S_w, S_Y = S[:, :nw], S[:, nw:]
        nR = int(R.shape[0])
        # The chain rule through the interval templates: every product of a block of their
        # mapped derivatives with constant selections is a constant linear map of the block's
        # nonzeros (_Scatter: one sparse matrix-vector product per evaluation, nothing
        # derived); only the products with the few non-constant rows of the ratio objective
        # (L_wR, L_YR) stay MX products.
        G_R_const = not ca.depends_on(G_R, ca.vertcat(w, Y, R))
        self._jac = ca.Function("outer_jac", [w, Y, R], [G, G_w, G_Y] +
                                ([] if G_R_const else [G_R]))
        jac_block = self._block_sparsity([d.jacobian.sparsity_out(1) for d in self.derivs])
        hess_J = self._block_sparsity([d.hessian.sparsity_out(0) for d in self.derivs])
        hess_H = self._block_sparsity([d.hessian.sparsity_out(2) for d in self.derivs])
        # The second derivatives of the residual Lagrangian couple R to (w, Y) through the
        # objective's ratio: through the interval costs only, unless a differentiated row of
        # G reads other interval terms (then the whole Jacobian of r is needed).
        costs, pos = [], 0
        for ig in self.intervals:
            nr, N = int(ig.r.shape[0]), int(ig.r.shape[1])
            costs.append(pos + nr * np.arange(N) + nr - 1)
            pos += nr * N
        cost_rows = np.concatenate(costs)
        used = {int(c) for m in (L_wR, L_YR) for c in m.sparsity().get_col()}
        used |= {int(c) for c in L_RR.sparsity().get_col()}
        self._costs_only = used <= set(cost_rows.tolist())
        if self._costs_only:
            place = ca.DM.triplet(cost_rows.tolist(), list(range(cost_rows.size)),
                                  [1.0] * cost_rows.size, nR, cost_rows.size)
        else:
            place, hess_J = ca.DM.eye(nR), jac_block
        self._jac_block = jac_block
        if G_R_const:
            C = ca.evalf(G_R)
            self._G_R = None
            self._jac_w, self._jac_Y = _Scatter(C, jac_block, S_w), _Scatter(C, jac_block, S_Y)
        else:
            self._G_R = True
        self._A_w, self._A_Y = _Scatter(place, hess_J, S_w), _Scatter(place, hess_J, S_Y)
        self._H_ww = _Scatter(S_w.T, hess_H, S_w)
        self._H_wY = _Scatter(S_w.T, hess_H, S_Y)
        self._H_YY = _Scatter(S_Y.T, hess_H, S_Y)
        self._S_Y_T = S_Y.T
        self._hess = ca.Function("outer_hess", [w, Y, R, sigma, lam],
                                 [L_ww, L_wY, L_YY, L_Y, L_wR, L_YR, L_RR])

    def _block_sparsity(self, blocks: list[ca.Sparsity]) -> ca.Sparsity:
        """The block-diagonal sparsity of the interval groups' blocks (N copies of each
        group's block), whose nonzeros are in the order of the mapped outputs'."""
        mats = [ca.diagcat(*[ca.DM(b, 1.0)] * int(ig.r.shape[1])).sparsity()
                for b, ig in zip(blocks, self.intervals, strict=True)]
        return ca.diagcat(*[ca.DM(m, 1.0) for m in mats]).sparsity()

    def _inputs(self, W: ca.MX, Yv: ca.MX) -> list[ca.MX]:
        """The inputs v (nv, N) of each interval group."""
        U = ca.vertcat(W, Yv)
        if self._pick is not None:  # a selection: indexing and scaling, not a product
            cols, scale = self._pick
            V = U[cols] * scale
        else:
            V = ca.mtimes(self.S, U)
        out, pos = [], 0
        for ig in self.intervals:
            nv, N = int(ig.v.shape[0]), int(ig.v.shape[1])
            out.append(ca.reshape(V[pos:pos + nv * N], nv, N))
            pos += nv * N
        return out

    def _values(self, Vs: list[ca.MX]) -> ca.MX:
        if not self.intervals:
            return ca.MX(0, 1)
        return ca.vertcat(*[ca.vec(d.value.map(int(ig.r.shape[1]))(v, ig.dtau))
                            for d, ig, v in zip(self.derivs, self.intervals, Vs, strict=True)])

    def g(self, W: ca.MX, Yv: ca.MX) -> ca.MX:
        """G at (W, Y)."""
        return self._g(W, Yv)

    def _inlined(self, expr: ca.SX, R: ca.SX) -> ca.SX:
        """``expr`` with the interval terms it reads as SX expressions of w and the point
        outputs (the interval templates inlined)."""
        if not self.intervals:
            return expr
        read = sorted(set(ca.jacobian_sparsity(expr, R).get_col()))
        if not read:
            return expr
        values = ca.vertcat(*[ca.vec(ig.template.map(int(ig.r.shape[1]))(ig.v, ig.dtau))
                              for ig in self.intervals])
        return ca.substitute(expr, R[read], values[read])

    def jacobian(self, W: ca.MX, Yv: ca.MX) -> tuple[ca.MX, ca.MX, ca.MX]:
        """(G, G_w, G_Y) at (W, Y)."""
        if not self.intervals:
            G, G_w, G_Y = self._jac(W, Yv, ca.MX(0, 1))
            return G, G_w, G_Y
        calls = [d.jacobian.map(int(ig.r.shape[1]))(v, ig.dtau)
                 for d, ig, v in zip(self.derivs, self.intervals, self._inputs(W, Yv),
                                     strict=True)]
        Rv = ca.vertcat(*[ca.vec(c[0]) for c in calls])
        nz = ca.vertcat(*[ca.vec(c[1].nz[:]) for c in calls])
        if self._G_R is None:
            G, G_w, G_Y = self._jac(W, Yv, Rv)
            return G, G_w + self._jac_w(nz), G_Y + self._jac_Y(nz)
        G, G_w, G_Y, G_R = self._jac(W, Yv, Rv)
        BJ = ca.MX(self._jac_block, nz)
        return (G, G_w + ca.mtimes([G_R, BJ, self.S[:, :self.nw]]),
                G_Y + ca.mtimes([G_R, BJ, self.S[:, self.nw:]]))

    def hessian(self, W: ca.MX, Yv: ca.MX, S: ca.MX, Lam: ca.MX
                ) -> tuple[ca.MX, ca.MX, ca.MX, ca.MX]:
        """(L_ww, L_wY, L_YY, L_Y) at (W, Y, sigma, lambda)."""
        if not self.intervals:
            L_ww, L_wY, L_YY, L_Y = self._hess(W, Yv, ca.MX(0, 1), S, Lam)
            return L_ww, L_wY, L_YY, L_Y
        Vs = self._inputs(W, Yv)
        Rv = self._values(Vs)
        L_R = self._mu(W, Yv, Rv, S, Lam)
        calls, pos = [], 0
        for d, ig, v in zip(self.derivs, self.intervals, Vs, strict=True):
            nr, N = int(ig.r.shape[0]), int(ig.r.shape[1])
            calls.append(d.hessian.map(N)(v, ig.dtau, ca.reshape(L_R[pos:pos + nr * N], nr, N)))
            pos += nr * N
        if self._costs_only:
            bj = ca.vertcat(*[ca.vec(c[0].nz[:]) for c in calls])
        else:
            bj = ca.vertcat(*[ca.vec(d.jacobian.map(int(ig.r.shape[1]))(v, ig.dtau)[1].nz[:])
                              for d, ig, v in zip(self.derivs, self.intervals, Vs,
                                                  strict=True)])
        bh = ca.vertcat(*[ca.vec(c[2].nz[:]) for c in calls])
        grads = ca.vertcat(*[ca.vec(c[1]) for c in calls])
        L_ww, L_wY, L_YY, L_Y, L_wR, L_YR, L_RR = self._hess(W, Yv, Rv, S, Lam)
        L_ww = L_ww + self._H_ww(bh)
        L_wY = L_wY + self._H_wY(bh)
        L_YY = L_YY + self._H_YY(bh)
        if L_wR.nnz() or L_YR.nnz() or L_RR.nnz():
            A_w, A_Y = self._A_w(bj), self._A_Y(bj)
            cross_w = ca.mtimes(L_wR, A_w)
            cross_Y = ca.mtimes(L_YR, A_Y)
            L_ww = L_ww + cross_w + cross_w.T
            L_wY = L_wY + ca.mtimes(L_wR, A_Y) + ca.mtimes(A_w.T, L_YR.T)
            L_YY = L_YY + cross_Y + cross_Y.T
            if L_RR.nnz() > 0:
                L_ww = L_ww + ca.mtimes([A_w.T, L_RR, A_w])
                L_wY = L_wY + ca.mtimes([A_w.T, L_RR, A_Y])
                L_YY = L_YY + ca.mtimes([A_Y.T, L_RR, A_Y])
        return L_ww, L_wY, L_YY, L_Y + ca.mtimes(self._S_Y_T, grads)

    def objective(self, F: ca.SX) -> ca.SX:
        """``F`` with the interval terms it reads (the interval costs) as SX expressions of w
        and the point outputs (the interval templates inlined)."""
        if not self.intervals:
            return F
        return self._inlined(F, ca.vertcat(*[ca.vec(ig.r) for ig in self.intervals]))


def build_pointwise(assembly: Assembly, groups: list[_Group], compile_c: bool,
                    intervals: list[_IntervalGroup] | None = None) -> PointwiseNlp:
    """The exact derivative functions of the SX ``assembly`` whose point outputs are the
    recorded ``groups`` and whose interval terms are the recorded ``intervals`` (see the
    module docstring and ``_Outer``)."""
    w = assembly.w_hat
    nw = int(w.shape[0])
    ng = int(assembly.g.shape[0])
    Y = ca.vertcat(*[ca.vec(gr.y) for gr in groups])
    Z = ca.vertcat(*[ca.vec(gr.z) for gr in groups])
    outer = _Outer(assembly, Y, intervals or [])
    nu = ca.SX.sym("nu", Z.shape[0])
    Dz_sym = _linear_jacobian(Z, w)
    z_of_w = ca.Function("z_of_w", [w], [Z, Dz_sym])
    # Hess_w (nu^T z(w)) vanishes where the point inputs are affine in w (fixed durations, or
    # durations affine in the parameters): then it is not derived. Else only the inputs whose
    # Jacobian depends on w enter it (the times, through the durations), not the mesh's
    # states and controls.
    curved = [int(i) for i in np.flatnonzero(ca.which_depends(Z, w, 2, True))]
    z_hess = None
    if curved:
        hess = ca.hessian(ca.dot(nu[curved], Z[curved]), w)[0]
        z_hess = ca.Function("z_hess", [w, nu], [hess])

    derivs = point_derivatives([gr.point for gr in groups], compile_c)
    W, P = ca.MX.sym("w", nw), ca.MX.sym("p", 0)
    Zv, Dz = z_of_w(W)
    sizes = [(int(gr.z.shape[0]), int(gr.y.shape[0]), int(gr.z.shape[1])) for gr in groups]

    def split(v: ca.MX, rows_of: int) -> list[ca.MX]:
        out, pos = [], 0
        for s in sizes:
            rows, M = s[rows_of], s[2]
            out.append(ca.reshape(v[pos:pos + rows * M], rows, M))
            pos += rows * M
        return out

    Zs = split(Zv, 0)

    def values() -> ca.MX:
        return ca.vertcat(*[ca.vec(d.value.map(s[2])(z))
                            for d, s, z in zip(derivs, sizes, Zs, strict=True)])

    def jacobian_of_points(jac_outputs: list[ca.MX]) -> ca.MX:
        blocks = [_block_diagonal(Jm, d.jacobian.sparsity_out(1), s[2])
                  for d, s, Jm in zip(derivs, sizes, jac_outputs, strict=True)]
        return ca.diagcat(*blocks)

    Yv = values()
    # The objective as one SX graph with the point outputs it reads (the integrand L) inlined
    # at every point, and its gradient by reverse AD of that graph: small next to the
    # dynamics, and smaller than the point Jacobians the chain rule would need.
    F = outer.objective(assembly.f)
    F_sx = ca.substitute(F, *_inlined_outputs(F, groups))
    P_sx = ca.SX.sym("p", 0)
    fns: dict[str, ca.Function] = {
        "nlp_f": ca.Function("nlp_f", [w, P_sx], [F_sx], ["x", "p"], ["f"]),
        "nlp_g": ca.Function("nlp_g", [W, P], [outer.g(W, Yv)], ["x", "p"], ["g"]),
        "nlp_grad_f": ca.Function("nlp_grad_f", [w, P_sx], [F_sx, ca.gradient(F_sx, w)],
                                  ["x", "p"], ["f", "grad_f_x"]),
    }
    jac_calls = [d.jacobian.map(s[2])(z) for d, s, z in zip(derivs, sizes, Zs, strict=True)]
    Yj = ca.vertcat(*[ca.vec(c[0]) for c in jac_calls])
    JD = ca.mtimes(jacobian_of_points([c[1] for c in jac_calls]), Dz)
    g1, G_w, G_Y = outer.jacobian(W, Yj)
    fns["nlp_jac_g"] = ca.Function("nlp_jac_g", [W, P], [g1, G_w + ca.mtimes(G_Y, JD)],
                                   ["x", "p"], ["g", "jac_g_x"])

    S, Lam = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", ng)
    L_ww, L_wY, L_YYv, mu = outer.hessian(W, Yv, S, Lam)
    mus = split(mu, 1)
    hess_calls = [d.hessian.map(s[2])(z, m)
                  for d, s, z, m in zip(derivs, sizes, Zs, mus, strict=True)]
    JBh = jacobian_of_points([c[0] for c in hess_calls])
    HB = ca.diagcat(*[_block_diagonal(Hm, d.hessian.sparsity_out(1), s[2])
                      for d, s, Hm in zip(derivs, sizes, [c[1] for c in hess_calls],
                                          strict=True)])
    JDh = ca.mtimes(JBh, Dz)
    cross = ca.mtimes(L_wY, JDh)
    H = L_ww + cross + cross.T + ca.mtimes([Dz.T, HB, Dz])
    if z_hess is not None:
        H = H + z_hess(W, ca.mtimes(JBh.T, mu))
    if L_YYv.nnz() > 0:
        H = H + ca.mtimes([JDh.T, L_YYv, JDh])
    fns["nlp_hess_l"] = ca.Function("nlp_hess_l", [W, P, S, Lam], [ca.triu(H)],
                                    ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])
    return PointwiseNlp(fns, compiled=all(d.compiled for d in derivs),
                        point_functions=tuple(gr.point for gr in groups),
                        point_evaluators=tuple(unstacked_value(gr.point, d.value)
                                               if d.compiled else gr.point
                                               for gr, d in zip(groups, derivs, strict=True)))


def unstacked_value(point: ca.Function, value: ca.Function) -> ca.Function:
    """``point``'s own signature (its inputs, e.g. ``(x, u, p, t)``, and outputs, e.g.
    ``(xdot, path, L)``) evaluated through ``value(z) -> y`` of its :func:`stacked_point`
    form (e.g. the compiled library's): the values a result reports, without CasADi's VM."""
    args = [ca.MX.sym(point.name_in(i), point.sparsity_in(i)) for i in range(point.n_in())]
    y = value(ca.vertcat(*args))
    sizes = [point.size1_out(i) for i in range(point.n_out())]
    outs = ca.vertsplit(y, np.concatenate([[0], np.cumsum(sizes)]).astype(int).tolist())
    return ca.Function(point.name(), args, outs, point.name_in(), point.name_out())
