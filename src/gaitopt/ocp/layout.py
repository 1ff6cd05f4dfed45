"""Names for the entries of the flat NLP vectors: decision variables w and constraints g.

Decision vector order (the documented contract; never index it by hand, use a Layout)::

    w = [ phase 0 block, phase 1 block, ..., parameters p (n_p) ]
    phase block = [ T (only if the duration is free),
                    x_0 (n), u_0 (m), x_1 (n), u_1 (m), ..., x_{K-1} (n), u_{K-1} (m),
                    x_m0 (n), x_m1 (n), ..., x_m{N-1} (n)   (separated Hermite-Simpson only) ]

Knot-major interleaving keeps the constraint Jacobian banded. Compressed Hermite-Simpson and
trapezoidal transcriptions have no midpoint variables; the separated Hermite-Simpson form
appends the midpoint state of every interval after the knots of its phase.

Constraint vector order::

    g = [ for each phase: defects (N intervals x n, interval-major),
                          midpoint defects (N x n, separated Hermite-Simpson only),
                          path constraints at knots (K x r_knots, knot-major),
                          path constraints at midpoints (N x r_mid, interval-major),
                          duration bounds (1 row, only for bounded expression durations),
          for each linkage (in problem order): its rows,
          for each boundary constraint (in problem order): its rows ]
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class PhaseLayout:
    """Where one phase's variables sit in w.

    ``start`` is the index of ``x_0[0]``; knot k occupies ``[start + k*stride, start +
    (k+1)*stride)`` with ``stride = n + m``, states first. With ``midpoints = N`` (separated
    Hermite-Simpson) the midpoint state of interval k follows the knots at
    ``[midpoint_start + k*n, midpoint_start + (k+1)*n)``; otherwise ``midpoints = 0``.
    """

    name: str
    states: tuple[str, ...]
    controls: tuple[str, ...]
    knots: int
    start: int
    duration_index: int | None
    midpoints: int = 0

    @property
    def stride(self) -> int:
        """n + m: entries per knot."""
        return len(self.states) + len(self.controls)

    @property
    def intervals(self) -> int:
        """N = K - 1."""
        return self.knots - 1

    @property
    def midpoint_start(self) -> int:
        """Index of the first midpoint state (one past the last knot variable)."""
        return self.start + self.knots * self.stride

    @property
    def end(self) -> int:
        """One past the last index of the phase block."""
        return self.midpoint_start + self.midpoints * len(self.states)

    def knot_block(self) -> slice:
        """All knot variables, reshapeable to (K, n + m) row-major."""
        return slice(self.start, self.midpoint_start)

    def midpoint_block(self) -> slice:
        """All midpoint states, reshapeable to (midpoints, n) row-major (empty if none)."""
        return slice(self.midpoint_start, self.end)

    def _offset(self, kind: str, name: str) -> int:
        if kind == "state":
            names = self.states
            base = 0
        elif kind == "control":
            names = self.controls
            base = len(self.states)
        else:
            raise KeyError(f"kind must be 'state' or 'control', got {kind!r}")
        try:
            return base + names.index(name)
        except ValueError:
            raise KeyError(f"phase {self.name!r} has no {kind} {name!r} "
                           f"(has {list(names)})") from None

    def index(self, kind: str, name: str, knot: int) -> int:
        """Index in w of ``kind`` ('state'/'control') ``name`` at knot ``knot`` (negative ok)."""
        k = knot + self.knots if knot < 0 else knot
        if not 0 <= k < self.knots:
            raise IndexError(f"phase {self.name!r}: knot {knot} out of range [0, {self.knots})")
        return self.start + k * self.stride + self._offset(kind, name)

    def across_knots(self, kind: str, name: str) -> slice:
        """Slice of w giving ``name`` at every knot, (K,)."""
        first = self.start + self._offset(kind, name)
        return slice(first, self.midpoint_start, self.stride)

    def across_midpoints(self, name: str) -> slice:
        """Slice of w giving state ``name`` at every midpoint, (midpoints,) (empty if none)."""
        first = self.midpoint_start + self._offset("state", name)
        return slice(first, self.end, len(self.states))

    def midpoint_index(self, name: str, interval: int) -> int:
        """Index in w of state ``name`` at the midpoint of ``interval`` (negative ok)."""
        k = interval + self.midpoints if interval < 0 else interval
        if not 0 <= k < self.midpoints:
            raise IndexError(f"phase {self.name!r}: midpoint {interval} out of range "
                             f"[0, {self.midpoints})")
        return self.midpoint_start + k * len(self.states) + self._offset("state", name)

    def midpoint_indices(self) -> NDArray[np.int64]:
        """Indices of all midpoint states, (midpoints, n) ((0, n) if none)."""
        n = len(self.states)
        grid = self.midpoint_start + n * np.arange(self.midpoints)[:, None]
        return np.asarray(grid + np.arange(n)[None, :], dtype=np.int64).reshape(
            self.midpoints, n)

    def state_indices(self) -> NDArray[np.int64]:
        """Indices of all states, (K, n)."""
        grid = self.start + self.stride * np.arange(self.knots)[:, None]
        return np.asarray(grid + np.arange(len(self.states))[None, :], dtype=np.int64)

    def control_indices(self) -> NDArray[np.int64]:
        """Indices of all controls, (K, m)."""
        grid = self.start + self.stride * np.arange(self.knots)[:, None] + len(self.states)
        return np.asarray(grid + np.arange(len(self.controls))[None, :], dtype=np.int64)


@dataclass(frozen=True)
class Layout:
    """The decision-vector layout of a transcription (see the module docstring)."""

    phases: tuple[PhaseLayout, ...]
    parameters: tuple[str, ...]
    parameter_start: int
    size: int

    @staticmethod
    def build(phase_specs: Sequence[tuple[str, Sequence[str], Sequence[str], int, bool]],
              parameters: Sequence[str], *, midpoint_states: bool = False) -> Layout:
        """Lay out phases ``(name, states, controls, knots, has_free_duration)`` then p;
        ``midpoint_states`` appends the N midpoint states of each phase after its knots."""
        pos = 0
        out = []
        for name, states, controls, knots, free in phase_specs:
            dur = None
            if free:
                dur = pos
                pos += 1
            mids = int(knots) - 1 if midpoint_states else 0
            pl = PhaseLayout(name, tuple(states), tuple(controls), int(knots), pos, dur, mids)
            out.append(pl)
            pos = pl.end
        return Layout(tuple(out), tuple(parameters), pos, pos + len(parameters))

    def phase(self, key: int | str) -> PhaseLayout:
        """A phase's layout by position or name."""
        if isinstance(key, int):
            return self.phases[key]
        for pl in self.phases:
            if pl.name == key:
                return pl
        raise KeyError(f"no phase {key!r} (phases: {[pl.name for pl in self.phases]})")

    def parameter(self, name: str) -> int:
        """Index in w of parameter ``name``."""
        try:
            return self.parameter_start + self.parameters.index(name)
        except ValueError:
            raise KeyError(f"no parameter {name!r} (parameters: {list(self.parameters)})") \
                from None

    def parameter_slice(self) -> slice:
        """Slice of w holding p."""
        return slice(self.parameter_start, self.size)

    def index(self, phase: int | str, kind: str, name: str = "", knot: int = 0) -> int:
        """Index in w of (phase, kind, name, knot); kind in state/control/duration/parameter."""
        if kind == "parameter":
            return self.parameter(name)
        pl = self.phase(phase)
        if kind == "duration":
            if pl.duration_index is None:
                raise KeyError(f"phase {pl.name!r} has no free duration variable")
            return pl.duration_index
        return pl.index(kind, name, knot)

    def signature(self) -> tuple[object, ...]:
        """Equal for layouts with the same variables in the same places."""
        return (tuple((p.name, p.states, p.controls, p.knots, p.duration_index, p.midpoints)
                      for p in self.phases), self.parameters)


@dataclass(frozen=True)
class ConstraintBlock:
    """A named run of rows of g: ``rows`` and its logical ``shape`` (row-major in rows)."""

    name: str
    phase: str | None
    kind: str
    rows: slice
    shape: tuple[int, ...]


@dataclass(frozen=True)
class ConstraintLayout:
    """The constraint-vector layout (see the module docstring)."""

    blocks: tuple[ConstraintBlock, ...]
    size: int

    def block(self, name: str) -> ConstraintBlock:
        """The block called ``name`` (e.g. ``"walk/defects"``, ``"linkage a->b"``)."""
        for b in self.blocks:
            if b.name == name:
                return b
        raise KeyError(f"no constraint block {name!r} (blocks: {[b.name for b in self.blocks]})")

    def row_names(self) -> list[str]:
        """A readable name for every row (for diagnostics)."""
        out = [""] * self.size
        for b in self.blocks:
            for i, r in enumerate(range(b.rows.start, b.rows.stop)):
                out[r] = f"{b.name}[{i}]"
        return out
