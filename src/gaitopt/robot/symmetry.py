"""Left/right symmetry: which links and contact points swap roles after a step.

A symmetric periodic gait repeats with the legs exchanged. A model says how, either in its
file (``symmetry: {links: [[thigh_1, thigh_2], ...], contacts: [[tip_1, tip_2]]}``) or, when
it does not, gaitopt infers it: the chains of links from the floating base to the first two
contact points are the two legs, paired link by link in order. Joints swap with the links
they move, joint actuators with their joints, contact actuators with their contacts; every
other link, joint and actuator maps to itself.

``q_swapped = q[perm_q]`` exchanges the legs' coordinates (the base coordinates ``x, y`` and
the base angle stay), ``u_swapped = u[perm_u]`` their actuators; both are involutions.
:func:`leg_swap` holds both with the contact map, built once per model.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from gaitopt.robot.model import RobotModel


class SymmetryError(ValueError):
    """A model has no usable left/right symmetry (none declared and none can be inferred, or
    the declared one does not map the model onto itself)."""


@dataclass(frozen=True)
class Symmetry:
    """Pairs of links and of contact points that swap, and where they came from."""

    links: tuple[tuple[str, str], ...]
    contacts: tuple[tuple[str, str], ...]
    source: Literal["declared", "inferred"]

    def describe(self) -> str:
        """One line for people, e.g. ``thigh_1 <-> thigh_2, ... (inferred from ...)``."""
        pairs = ", ".join(f"{a} <-> {b}" for a, b in self.links + self.contacts)
        how = ("declared in the model file" if self.source == "declared" else
               "inferred: the chains from the base to the first two contact points")
        return f"{pairs} ({how})"


def model_symmetry(model: RobotModel) -> Symmetry:
    """The declared symmetry of ``model``, or the inferred one (module docstring).

    Raises:
        SymmetryError: none declared and the model does not have two contact points on two
            separate chains of equal length from the base.
    """
    if model.symmetry is not None:
        return Symmetry(model.symmetry.links, model.symmetry.contacts, "declared")
    hint = ("declare it in the model file: symmetry: {links: [[left, right], ...], "
            "contacts: [[left, right]]}")
    if len(model.contacts) < 2:
        raise SymmetryError(f"model {model.name!r}: no left/right symmetry can be inferred "
                            f"from {len(model.contacts)} contact point(s); {hint}")
    c1, c2 = model.contacts[0], model.contacts[1]
    legs = [model.chain(model.link_index(c.link))[1:] for c in (c1, c2)]
    if len(legs[0]) != len(legs[1]) or set(legs[0]) & set(legs[1]) or not legs[0]:
        raise SymmetryError(
            f"model {model.name!r}: no left/right symmetry can be inferred: the chains from "
            f"the base to {c1.name!r} and {c2.name!r} are not two separate chains of equal "
            f"length; {hint}")
    pairs = tuple((model.links[a].name, model.links[b].name)
                  for a, b in zip(legs[0], legs[1], strict=True))
    return Symmetry(pairs, ((c1.name, c2.name),), "inferred")


def _mapping(pairs: tuple[tuple[str, str], ...]) -> dict[str, str]:
    out: dict[str, str] = {}
    for a, b in pairs:
        out[a], out[b] = b, a
    return out


def swap_maps(model: RobotModel) -> tuple[dict[str, str], dict[str, str]]:
    """Link and contact name maps of the swap (every name maps to itself unless paired)."""
    sym = model_symmetry(model)
    links = {link.name: link.name for link in model.links} | _mapping(sym.links)
    contacts = {c.name: c.name for c in model.contacts} | _mapping(sym.contacts)
    return links, contacts


def swap_names(model: RobotModel) -> dict[str, str]:
    """Every link, joint and contact name of ``model`` -> its counterpart after the swap
    (itself unless paired): the relabelling of named points (e.g. a gait's ``knee_1``,
    ``heel_1``) when the legs exchange roles."""
    links, contacts = swap_maps(model)
    out = dict(links) | dict(contacts)
    for link in model.links:
        other = model.link(links[link.name]).joint
        if link.joint is not None and other is not None:
            out[link.joint.name] = other.name
    return out


def swap_permutations(model: RobotModel) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Index permutations of ``q`` (nq,) and ``u`` (nu,) that exchange the legs.

    Raises:
        SymmetryError: the swap does not map the model onto itself (a paired link's parent
            is not the pair of the other's parent, a contact's link is not paired with the
            other's, an actuator has no counterpart).
    """
    links, contacts = swap_maps(model)
    name = model.name
    for a, b in links.items():
        la, lb = model.link(a), model.link(b)
        if (la.parent is None) != (lb.parent is None) or (
                la.parent is not None and links[la.parent] != lb.parent):
            raise SymmetryError(f"model {name!r}: symmetry pairs {a!r} with {b!r}, but their "
                                f"parents {la.parent!r} and {lb.parent!r} are not a pair")
    for a, b in contacts.items():
        if links[model.contact(a).link] != model.contact(b).link:
            raise SymmetryError(f"model {name!r}: symmetry pairs contacts {a!r} and {b!r}, "
                                "but their links are not a pair")
    perm_q = np.arange(model.nq)
    joint_of = {}
    for i, link in enumerate(model.links[1:], start=1):
        other = model.link_index(links[link.name])
        perm_q[model.coordinate_of_link(i)] = model.coordinate_of_link(other)
        other_joint = model.links[other].joint
        if link.joint is not None and other_joint is not None:
            joint_of[link.joint.name] = other_joint.name
    perm_u = np.arange(model.nu)
    for i, act in enumerate(model.actuators):
        target = (joint_of.get(act.joint, act.joint) if act.joint is not None
                  else contacts.get(act.contact or "", act.contact))
        matches = [j for j, b in enumerate(model.actuators)
                   if (b.joint if act.joint is not None else b.contact) == target]
        if len(matches) != 1:
            raise SymmetryError(f"model {name!r}: actuator {act.name!r} has no unique "
                                "counterpart on the other side")
        perm_u[i] = matches[0]
    return perm_q, perm_u


@dataclass(frozen=True)
class LegSwap:
    """How the legs swap after a step: permutations of ``q`` (nq,) and ``u`` (nu,), and the
    contact names (every contact -> its counterpart, itself unless paired)."""

    perm_q: tuple[int, ...]
    perm_u: tuple[int, ...]
    contacts: Mapping[str, str]


@functools.lru_cache(maxsize=16)
def leg_swap(model: RobotModel) -> LegSwap:
    """The leg swap of ``model`` (declared in its file or inferred: :func:`model_symmetry`),
    built once per model.

    Raises:
        SymmetryError: as :func:`swap_permutations`.
    """
    perm_q, perm_u = swap_permutations(model)
    _, contacts = swap_maps(model)
    return LegSwap(tuple(int(i) for i in perm_q), tuple(int(i) for i in perm_u), contacts)
