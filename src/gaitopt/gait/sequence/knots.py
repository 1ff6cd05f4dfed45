"""Knots per phase by name: the phase names of the built-in gaits and the one resolution of a
``knots`` option into counts in phase order.

``GaitOptions.knots`` (:mod:`gaitopt.gait.options.gait_options`) takes three forms:

* ``(first, others)``, two integers: phase 0 gets ``first`` knots and every later phase at
  least ``others`` (the paper's single and double support for the two-phase walk; for longer
  steps :func:`gaitopt.gait.sequence.contact_sequence.phase_knots` gives a long phase more);
* one integer per phase of the step, in phase order (a step of more than two phases);
* a mapping phase name -> count naming every phase of the step, e.g. ``{"single_support":
  16, "double_support": 6}`` for the walk, or the heel-toe walk's four
  (:data:`BUILTIN_PHASES`).

:func:`knots_in_order` turns the mapping into the counts in phase order (refusing a name that
is not a phase of the step, listing the phase names); every place that needs counts per phase
goes through it (the options' ``knots`` shorthand and
:func:`~gaitopt.gait.sequence.contact_sequence.phase_knots`). Standard library only: ``from
gaitopt import GaitOptions`` imports this module.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

#: The phase names of one step of each built-in gait (:mod:`gaitopt.gait.sequence.builtin`
#: names its phases from here): the walk, the single-support walk (single support fraction
#: 1), the run and the heel-toe walk.
BUILTIN_PHASES: dict[str, tuple[str, ...]] = {
    "walk": ("single_support", "double_support"),
    "walk-single-support": ("single_support",),
    "run": ("stance", "flight"),
    "heel-toe": ("foot_flat", "heel_off", "double_support", "heel_rocker"),
}


class KnotsError(ValueError):
    """A ``knots`` mapping names a phase the step lacks, or leaves one out (the message lists
    the step's phase names)."""


def is_named(knots: Any) -> bool:
    """Whether ``knots`` is the mapping form (phase name -> count)."""
    return isinstance(knots, Mapping)


def knots_in_order(knots: Mapping[str, int], phases: Sequence[str],
                   where: str = "knots") -> tuple[int, ...]:
    """The counts of a ``knots`` mapping in the order of ``phases`` (the phase names of one
    step).

    Raises:
        KnotsError: a name that is not one of ``phases``, or a phase left out (the message
            names ``where`` and lists the phase names).
    """
    names = ", ".join(phases)
    unknown = [str(k) for k in knots if k not in phases]
    if unknown:
        raise KnotsError(f"{where}: {', '.join(map(repr, unknown))} "
                         f"{'is not a phase' if len(unknown) == 1 else 'are not phases'} of "
                         f"the step (its phases: {names})")
    missing = [p for p in phases if p not in knots]
    if missing:
        raise KnotsError(f"{where}: give the knots of every phase of the step ({names}); "
                         f"missing: {', '.join(missing)}")
    return tuple(knots[p] for p in phases)


def knots_text(knots: Any) -> str:
    """``16+6`` for counts, ``single_support=16, double_support=6`` for the mapping."""
    if is_named(knots):
        return ", ".join(f"{k}={v}" for k, v in knots.items())
    return "+".join(str(k) for k in knots)
