"""Regridding a solution: its values AND multipliers mapped onto another grid of its problem.

A :class:`~gaitopt.ocp.Result` is a guess on any mesh (:func:`~gaitopt.ocp.guess.guess_vector`
evaluates its interpolants at the new knots), but its multipliers fit only its own layout.
:func:`regridded` maps them too, block by block, in normalised phase time tau, with the
scaling the KKT conditions of the transcribed problem imply. For an integral cost
``J = sum_k w_k L(z_k)`` (quadrature weights ``w_k`` proportional to the interval lengths h)
the stationarity of the Lagrangian at a grid point reads
``w_k L_z(z_k) + sum_rows lambda_row d(row)/dz_k = 0``, so

* a row stated once per grid point whose derivative does not contain h (a path constraint
  ``c(z_k)``, a variable bound) has a multiplier ``w_k mu(t_k)`` with mu the continuous
  multiplier density: it is mapped as ``lambda_new = w_new mu(tau_new)`` with
  ``mu = lambda_old / w_old`` interpolated linearly;
* a collocation defect ``x_{k+1} - x_k - h (...)`` has a multiplier that approximates the
  costate ``lambda(t)`` (the difference of neighbouring defect multipliers is O(h) and
  balances the O(h) terms): mapped by value, no weight;
* the separated Hermite-Simpson midpoint defect ``x_m - (x_k + x_{k+1})/2 - h (f_k -
  f_{k+1})/8`` is the only row holding the midpoint state ``x_m`` without a factor h, while
  the Simpson defect and the quadrature weigh ``x_m`` by ``4 h / 6``: its multiplier is
  ``(2 h / 3) (lambda^T f_x - L_x)`` at the midpoint, O(h): mapped like a path row with the
  interval length as weight.

Weights (normalised; only their ratios within a block matter): a knot ``(dtau_{k-1} +
dtau_k) / 2`` (half an interval at the phase ends), a midpoint or interval ``dtau_k``. Rows
and variables that do not belong to the grid (phase durations, parameters, linkages, boundary
constraints, bounded duration expressions) keep their multipliers. The rows at a phase's
first and last knot (path constraints, variable bounds) may also hold a condition at the
phase end whose multiplier is O(1), not a density (a fixed initial state's bound carries the
costate there; the walk's contact rows at its events): their multiplier is split into the
density part (the neighbouring knot's density times their weight) and the rest, which is
kept.

The mapping needs the same problem (phases, their states and controls, which durations are
free, parameters, constraint rows per point) and method; anything else is a
:class:`~gaitopt.ocp.validate.ProblemError`. Interval-major blocks (N, c) are located at the
interval centres, knot-major blocks (K, c) at the knots (:mod:`gaitopt.ocp.layout`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.guess import WarmStart, guess_vector
from gaitopt.ocp.layout import ConstraintBlock, Layout
from gaitopt.ocp.result import METHODS, Result
from gaitopt.ocp.validate import ProblemError

if TYPE_CHECKING:
    from gaitopt.ocp.transcription import Transcription

Array = NDArray[np.float64]

#: Constraint blocks of a phase by the suffix of their name: where their rows sit
#: ("knots" (K, c) or "intervals" (N, c)) and whether the multiplier is a density (scaled by
#: the quadrature weight) or a value (the costate of a defect).
PHASE_BLOCKS: dict[str, tuple[str, bool]] = {
    "defects": ("intervals", False),
    "midpoint defects": ("intervals", True),
    "path@knots": ("knots", True),
    "path@midpoints": ("intervals", True),
}


@dataclass(frozen=True)
class GridPoints:
    """Where the rows of a block sit on one phase's mesh: normalised times ``tau`` (M,) and
    quadrature weights ``weight`` (M,), for knots (M = K) or interval centres (M = N)."""

    tau: Array
    weight: Array

    @staticmethod
    def of(mesh: Array, where: str) -> GridPoints:
        """The knots (weights ``(dtau_{k-1} + dtau_k) / 2``) or the interval centres
        (weights ``dtau_k``) of ``mesh`` (K,)."""
        dtau = np.diff(mesh)
        if where == "intervals":
            return GridPoints(0.5 * (mesh[:-1] + mesh[1:]), dtau)
        weight = np.zeros(mesh.size)
        weight[:-1] += 0.5 * dtau
        weight[1:] += 0.5 * dtau
        return GridPoints(np.asarray(mesh, dtype=float), weight)


def map_block(values: Array, old: GridPoints, new: GridPoints, density: bool,
              ends: bool = False) -> Array:
    """Multipliers ``values`` (M_old, c) at ``old`` points onto ``new`` (M_new, c): linear
    interpolation in tau of the values, or with ``density`` of ``values / weight`` (then
    multiplied by the new weights). Beyond the old points the end values hold. With ``ends``
    (knot rows, at least 3 old and 2 new) the first and last rows are a boundary part plus
    the density part: the density there is taken from the neighbouring row, the rest is the
    boundary part (the multiplier of a condition that holds at the phase end), kept."""
    if values.shape[0] == 0:
        return np.zeros((new.tau.size, values.shape[1]))
    if not density:
        return np.stack([np.interp(new.tau, old.tau, col) for col in values.T], axis=1)
    dens = values / old.weight[:, None]
    ends = ends and values.shape[0] >= 3 and new.tau.size >= 2
    if ends:
        dens[0], dens[-1] = dens[1], dens[-2]
    out = np.stack([np.interp(new.tau, old.tau, col) for col in dens.T], axis=1)
    out *= new.weight[:, None]
    if ends:
        out[0] += values[0] - old.weight[0] * dens[0]
        out[-1] += values[-1] - old.weight[-1] * dens[-1]
    return out


def source_layout(tr: Transcription, result: Result) -> Layout:
    """The variable layout ``result`` was solved on: ``tr``'s problem on ``result.mesh``.
    Raises ProblemError when ``result`` is not a solution of ``tr``'s problem and method."""
    problem = tr.problem
    if result.method != tr.method:
        raise ProblemError(f"regrid: the result was solved by method {result.method!r}, the "
                           f"transcription uses {tr.method!r} (multipliers map only within "
                           "one method)")
    if len(result.mesh) != len(problem.phases):
        raise ProblemError(f"regrid: the result has {len(result.mesh)} phases, the problem "
                           f"{len(problem.phases)}: a result of another problem")
    old = Layout.build(
        [(ph.name, ph.states, ph.controls, tau.size, ph.duration_spec().kind == "free")
         for ph, tau in zip(problem.phases, result.mesh, strict=True)],
        problem.parameter_names, midpoint_states=METHODS[tr.method].midpoint_variables)
    if old.signature() != result.layout_signature:
        raise ProblemError("regrid: the result is of another problem (its phases, states, "
                           "controls, free durations or parameters differ from the "
                           "transcription's)")
    return old


def source_blocks(tr: Transcription, result: Result) -> list[ConstraintBlock | None]:
    """``tr``'s constraint blocks as they were on ``result``'s mesh (rows and shapes), in
    ``tr``'s order; None for a block without rows there (a phase of one knot). Raises
    ProblemError when their rows do not add up to ``result.lam_g``."""
    names = {ph.name: i for i, ph in enumerate(tr.problem.phases)}
    out: list[ConstraintBlock | None] = []
    start = 0
    for b in tr.nlp.constraints.blocks:
        shape = b.shape
        suffix = b.name.rsplit("/", 1)[-1]
        if b.phase is not None and suffix in PHASE_BLOCKS:
            knots = result.mesh[names[b.phase]].size
            lead = knots if PHASE_BLOCKS[suffix][0] == "knots" else knots - 1
            shape = (lead, *b.shape[1:])
        rows = int(np.prod(shape))
        out.append(ConstraintBlock(b.name, b.phase, b.kind, slice(start, start + rows), shape)
                   if rows else None)
        start += rows
    if start != result.lam_g.size:
        raise ProblemError(f"regrid: the result has {result.lam_g.size} constraint "
                           f"multipliers where the problem on its mesh has {start}: a result "
                           "of another problem")
    return out


def mapped_multipliers(tr: Transcription, result: Result) -> tuple[Array, Array]:
    """``result``'s multipliers on ``tr``'s grid: ``lam_x`` (tr.layout.size,) and ``lam_g``
    (tr.nlp.constraints.size,), unscaled like ``Result.lam_x, lam_g`` (see the module
    docstring). Raises ProblemError for a result of another problem or method."""
    old_layout = source_layout(tr, result)
    old_blocks = source_blocks(tr, result)
    lam_x = np.zeros(tr.layout.size)
    lam_g = np.zeros(tr.nlp.constraints.size)
    for pl, opl, tau, otau in zip(tr.layout.phases, old_layout.phases, tr.mesh, result.mesh,
                                  strict=True):
        if pl.duration_index is not None and opl.duration_index is not None:
            lam_x[pl.duration_index] = result.lam_x[opl.duration_index]
        knots = result.lam_x[opl.knot_block()].reshape(opl.knots, opl.stride)
        lam_x[pl.knot_block()] = map_block(knots, GridPoints.of(otau, "knots"),
                                           GridPoints.of(tau, "knots"), True, True).ravel()
        if pl.midpoints and opl.midpoints:
            mids = result.lam_x[opl.midpoint_block()].reshape(opl.midpoints, -1)
            lam_x[pl.midpoint_block()] = map_block(
                mids, GridPoints.of(otau, "intervals"), GridPoints.of(tau, "intervals"),
                density=True).ravel()
    lam_x[tr.layout.parameter_slice()] = result.lam_x[old_layout.parameter_slice()]
    meshes = dict(zip((ph.name for ph in tr.problem.phases), zip(result.mesh, tr.mesh,
                                                                  strict=True), strict=True))
    for new, old in zip(tr.nlp.constraints.blocks, old_blocks, strict=True):
        if old is None:
            continue
        values = result.lam_g[old.rows]
        suffix = new.name.rsplit("/", 1)[-1]
        if new.phase is None or suffix not in PHASE_BLOCKS:
            lam_g[new.rows] = values
            continue
        where, density = PHASE_BLOCKS[suffix]
        otau, tau = meshes[new.phase]
        lam_g[new.rows] = map_block(values.reshape(old.shape[0], -1),
                                    GridPoints.of(otau, where), GridPoints.of(tau, where),
                                    density, ends=where == "knots").ravel()
    return lam_x, lam_g


def regridded(tr: Transcription, result: Result) -> WarmStart:
    """A :class:`~gaitopt.ocp.WarmStart` for ``tr`` from ``result`` on another grid of its
    problem: the values ``result`` gives as a guess (its interpolants at ``tr``'s knots) and
    its multipliers mapped by :func:`mapped_multipliers`. Solve it with
    ``tr.solve(start, warm_start_multipliers=True)``."""
    lam_x, lam_g = mapped_multipliers(tr, result)
    w = guess_vector(tr.problem, tr.layout, tr.mesh, result)
    return WarmStart(w=w, lam_x=lam_x, lam_g=lam_g, layout=repr(tr.layout.signature()),
                     method=tr.method)
