"""Free phase fractions: which shares of the step time a contact sequence leaves free, the NLP
parameters that carry them, and each phase's share as a function of those parameters.

A phase of a :class:`~gaitopt.gait.contact_sequence.ContactSequence` with ``bounds`` has a free
share of the step time (its ``fraction`` is the first guess). Each free share but one is an NLP
parameter ``fraction_<phase>`` (:func:`fraction_parameters`); the last free phase takes the
remainder ``1 - (every other share)`` (:func:`phase_share`), so the shares sum to 1 by
construction, and its own bounds become a constraint row only where the other bounds do not
imply them (:func:`remainder_bounds`). Why a remainder and not a constraint ``sum = 1``: the
cold stages hold every fraction at its guess, where such an equality row has no free variable
(a zero row of the Jacobian: IPOPT's KKT matrix is singular), and a row that repeats a
parameter bound makes the constraints degenerate where that bound is active; for two phases
the remainder is exactly the single fraction ``f, 1 - f``.

:func:`with_free_fractions` frees every share of a sequence with default bounds
(``GaitOptions.free_phase_fractions``), :func:`with_first_fraction_bounds` phase 0 of two
(``GaitOptions.single_support_fraction_bounds``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.gait.contact_sequence import ContactSequence, ContactSequenceError

#: Default bounds of a freed fraction (:func:`with_free_fractions`), relative to its share
#: ``s``: ``[s / FREE_FRACTION_FACTOR, min(s * FREE_FRACTION_FACTOR, FREE_FRACTION_MAX)]``.
FREE_FRACTION_FACTOR = 2.0
FREE_FRACTION_MAX = 0.95
#: Prefix of the NLP parameter of a free fraction: ``fraction_<phase name>``.
FRACTION_PARAMETER = "fraction_"


@dataclass(frozen=True)
class FractionParameter:
    """The NLP parameter of a free phase fraction: ``name`` (``fraction_<phase>``), the
    phase's index, first guess and bounds."""

    name: str
    phase: int
    guess: float
    lower: float
    upper: float


def free_phases(seq: ContactSequence) -> tuple[int, ...]:
    """Indices of the phases whose fraction is free (has bounds)."""
    return tuple(i for i, ph in enumerate(seq.phases) if ph.free)


def fraction_parameters(seq: ContactSequence) -> tuple[FractionParameter, ...]:
    """The decision parameters of ``seq``'s free fractions: one per free phase but the last
    free one, which takes the remainder (module docstring), in phase order."""
    free = free_phases(seq)
    out = []
    for i in free[:-1]:
        ph = seq.phases[i]
        assert ph.bounds is not None
        out.append(FractionParameter(FRACTION_PARAMETER + ph.name, i, ph.fraction,
                                     float(ph.bounds[0]), float(ph.bounds[1])))
    return tuple(out)


def phase_share(seq: ContactSequence, i: int, values: Sequence[Any]) -> Any:
    """Phase ``i``'s share of the step time, ``values`` those of
    :func:`fraction_parameters` in order (numbers or symbols): its fraction when fixed, its
    parameter when free, and for the last free phase ``1 - sum of the other shares``."""
    params = fraction_parameters(seq)
    if len(values) != len(params):
        raise ValueError(f"sequence {seq.name!r}: {len(params)} fraction values expected, "
                         f"got {len(values)}")
    by_phase = {fp.phase: v for fp, v in zip(params, values, strict=True)}
    free = free_phases(seq)
    if i in by_phase:
        return by_phase[i]
    if not free or i != free[-1]:
        return seq.phases[i].fraction
    rest: Any = 0.0
    for k in range(len(seq.phases)):
        if k != i:
            rest = rest + phase_share(seq, k, values)
    return 1.0 - rest


def remainder_bounds(seq: ContactSequence) -> tuple[int, float, float] | None:
    """``(phase, lower, upper)``: the bounds of the remainder phase that its share must be
    held to by a constraint row, or None when there is no remainder or the other phases'
    bounds already imply them (two free phases, e.g.: a row would repeat a parameter bound,
    and a repeated active bound makes the constraints degenerate)."""
    free = free_phases(seq)
    if not free:
        return None
    last = free[-1]
    lo, hi = seq.phases[last].bounds or (0.0, 1.0)
    fixed = sum(ph.fraction for k, ph in enumerate(seq.phases) if k not in free)
    others = [seq.phases[k].bounds or (0.0, 0.0) for k in free[:-1]]
    implied_lo = 1.0 - fixed - sum(b[1] for b in others)
    implied_hi = 1.0 - fixed - sum(b[0] for b in others)
    if implied_lo >= lo - 1e-12 and implied_hi <= hi + 1e-12:
        return None
    return last, float(lo), float(hi)


def with_free_fractions(seq: ContactSequence, factor: float = FREE_FRACTION_FACTOR,
                        largest: float = FREE_FRACTION_MAX) -> ContactSequence:
    """``seq`` with every fixed fraction ``s`` freed within ``[s / factor, min(s factor,
    largest)]`` (phases already free keep their bounds)."""
    phases = tuple(ph if ph.free or len(seq.phases) == 1 else
                   dataclasses.replace(ph, bounds=(ph.fraction / factor,
                                                   max(ph.fraction,
                                                       min(ph.fraction * factor, largest))))
                   for ph in seq.phases)
    return dataclasses.replace(seq, phases=phases)


def with_shares(seq: ContactSequence, shares: Sequence[float]) -> ContactSequence:
    """``seq`` with each free phase's first guess set to its share in ``shares`` (one per
    phase, clipped to the phase's bounds; fixed phases keep theirs): the shares a solve found,
    which the knots per phase then follow (``GaitOptions.phase_shares``).

    Raises:
        ContactSequenceError: not one share per phase.
    """
    if len(shares) != len(seq.phases):
        raise ContactSequenceError(f"phase_shares: {len(shares)} share(s) for the "
                                   f"{len(seq.phases)} phases of sequence {seq.name!r}")
    fractions = [min(max(float(s), ph.bounds[0]), ph.bounds[1]) if ph.bounds is not None
                 else ph.fraction for ph, s in zip(seq.phases, shares, strict=True)]
    free = free_phases(seq)
    if free:
        # The shares a solve found sum to 1 within rounding, and may sit a bound's
        # relaxation (about 1e-8) outside a bound: what clipping took away goes to the free
        # phase with the most room for it, so that the guesses sum to 1.
        rest = 1.0 - math.fsum(fractions)
        room = [(seq.phases[i].bounds[1] - fractions[i]) if rest > 0.0  # type: ignore[index]
                else (fractions[i] - seq.phases[i].bounds[0]) for i in free]  # type: ignore[index]
        fractions[free[room.index(max(room))]] += rest
    phases = tuple(dataclasses.replace(ph, fraction=f)
                   for ph, f in zip(seq.phases, fractions, strict=True))
    return dataclasses.replace(seq, phases=phases)


def with_first_fraction_bounds(seq: ContactSequence, bounds: tuple[float, float]
                               ) -> ContactSequence:
    """A two-phase ``seq`` with phase 0's fraction ``f`` free within ``bounds`` (phase 1
    takes ``1 - f``): ``GaitOptions.single_support_fraction_bounds``."""
    if len(seq.phases) != 2:
        raise ContactSequenceError(f"sequence {seq.name!r}: single_support_fraction_bounds "
                                   f"needs a sequence of two phases; it has "
                                   f"{len(seq.phases)} (free_phase_fractions or fraction "
                                   "bounds in the sequence free any phase)")
    lo, hi = float(bounds[0]), float(bounds[1])
    first, second = seq.phases
    return dataclasses.replace(seq, phases=(
        dataclasses.replace(first, bounds=(lo, hi)),
        dataclasses.replace(second, bounds=(1.0 - hi, 1.0 - lo))))
