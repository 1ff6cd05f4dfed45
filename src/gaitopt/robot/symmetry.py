"""Left/right symmetry: which links and contact points swap roles after a step, and the linear
map of the coordinates that exchanges them.

A symmetric periodic gait repeats with the legs exchanged. A model says how, either in its
file (``symmetry: {links: [[thigh_1, thigh_2], ...], contacts: [[tip_1, tip_2]]}``) or, when
it does not, gaitopt infers it (:func:`model_symmetry`): the chains of links from the floating
base to the first two contact points, without the links they share, are the two legs, paired
link by link in order. When one chain is one link shorter, its first link is welded into the
last shared link (a leg that *is* the base, as the left thigh of Drake's kneed compass gait,
welded to the hip link): that link is then paired with the first link of the other leg.
Contact actuators swap with their contacts; every other link and contact maps to itself.

The swap is a linear map of the coordinates (:func:`swap_matrices`), derived from the
kinematics. With ``theta`` (n_links,) the absolute link angles (rad, world frame),

    theta = T q_a,    T[k, j] = 1 if link j is on the chain from the base to link k,

where ``q_a = q[2:]`` holds the base angle (link 0) and one relative joint angle per link
(``q[2 + k]`` is link k's). The swap exchanges the absolute angles of paired links and keeps
the others' (``theta' = P theta``, ``P`` the link permutation), so

    q_a' = T^-1 P T q_a,    q' = S q,   S = blockdiag(I_2, T^-1 P T)   (nq, nq)

and the base position ``x, y`` stays (the walking code shifts ``x`` by the step length).
``S`` is an involution (``P P = I``); velocities map the same way (``qd' = S qd``). When every
paired link's parent is paired with the other's parent, ``S`` is the permutation of the joint
coordinates; when a leg link is welded into the base, the base angle changes: for
``q = [x, y, base, hip, knee_1, knee_2]`` (hip the other thigh relative to the base),
``base' = base + hip``, ``hip' = -hip`` and the knees exchange.

Actuators map by the same link permutation (``u' = S_u u``, (nu, nu)): an actuator is a pair
of torques on links (a joint actuator +tau on its link, -tau on the parent; a contact
actuator +tau on its contact's link), and ``S_u`` takes each one to the actuator whose torque
pair is the permuted one, with a sign: the hip actuator of a welded leg maps to itself with
``u_hip' = -u_hip``. ``S_u`` is a signed permutation; a model whose permuted torques no single
actuator produces has no swap (:class:`SymmetryError`).

:func:`leg_swap` holds both maps with the contact map, built once per model.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

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
            separate chains from the base of equal length (or one link shorter: a leg
            welded into the link where the chains part).
    """
    if model.symmetry is not None:
        return Symmetry(model.symmetry.links, model.symmetry.contacts, "declared")
    hint = ("declare it in the model file: symmetry: {links: [[left, right], ...], "
            "contacts: [[left, right]]}")
    if len(model.contacts) < 2:
        raise SymmetryError(f"model {model.name!r}: no left/right symmetry can be inferred "
                            f"from {len(model.contacts)} contact point(s); {hint}")
    c1, c2 = model.contacts[0], model.contacts[1]
    chains = [model.chain(model.link_index(c.link)) for c in (c1, c2)]
    shared = 0
    while (shared < min(map(len, chains))
           and chains[0][shared] == chains[1][shared]):
        shared += 1
    legs = [list(chain[shared:]) for chain in chains]
    if legs[0] and legs[1]:  # two separate chains from the parting link
        if len(legs[0]) + 1 == len(legs[1]):  # leg 1's first link welded into it
            legs[0].insert(0, chains[0][shared - 1])
        elif len(legs[1]) + 1 == len(legs[0]):
            legs[1].insert(0, chains[1][shared - 1])
    if len(legs[0]) != len(legs[1]) or not legs[0]:
        raise SymmetryError(
            f"model {model.name!r}: no left/right symmetry can be inferred: the chains from "
            f"the base to {c1.name!r} and {c2.name!r} are not two separate chains of equal "
            f"length (nor one link shorter, its first link welded where they part); {hint}")
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
    ``heel_1``) when the legs exchange roles. A joint whose link is paired with the base
    (a welded leg) maps to itself."""
    links, contacts = swap_maps(model)
    out = dict(links) | dict(contacts)
    for link in model.links:
        other = model.link(links[link.name]).joint
        if link.joint is not None:
            out[link.joint.name] = other.name if other is not None else link.joint.name
    return out


def chain_matrix(model: RobotModel) -> NDArray[np.float64]:
    """``T`` (n_links, n_links): absolute link angles ``theta = T q[2:]`` (rad);
    ``T[k, j] = 1`` when link ``j`` is on the chain from the base to link ``k`` (inclusive).
    Unit lower triangular (parents come before their children), so invertible."""
    n = len(model.links)
    t = np.zeros((n, n))
    for k in range(n):
        t[k, list(model.chain(k))] = 1.0
    return t


def link_permutation(model: RobotModel) -> NDArray[np.float64]:
    """``P`` (n_links, n_links): ``(P theta)[k] = theta[swap(k)]``, the absolute angles after
    the swap (paired links exchange, the others stay)."""
    links, _ = swap_maps(model)
    n = len(model.links)
    p = np.zeros((n, n))
    for k, link in enumerate(model.links):
        p[k, model.link_index(links[link.name])] = 1.0
    return p


def actuator_torques(model: RobotModel) -> NDArray[np.float64]:
    """``A`` (n_links, nu): the torque (N m per unit of ``u``) each actuator puts on each
    link: a joint actuator +1 on its link and -1 on the parent, a contact actuator +1 on
    the link carrying its contact (the reaction on the ground is no link's)."""
    a = np.zeros((len(model.links), model.nu))
    for j, act in enumerate(model.actuators):
        if act.joint is not None:
            k = next(i for i, link in enumerate(model.links)
                     if link.joint is not None and link.joint.name == act.joint)
            a[k, j] += 1.0
            a[model.parent_index(k), j] -= 1.0
        else:
            a[model.link_index(model.contact(act.contact or "").link), j] += 1.0
    return a


def _check_pairs(model: RobotModel) -> None:
    """Raise :class:`SymmetryError` unless the pairs map the tree onto itself: paired links
    have paired parents (or the same one), or one is the other's parent with the joint at
    its origin (a welded leg, whose partner's hip is where the welded link's frame is);
    paired links point the same way and sit at the same point of their paired parents;
    paired contacts sit at the same point of paired links. (The kinematics, not the masses:
    a heavier leg keeps its swap, which only a symmetric gait needs to be exact.)"""
    links, contacts = swap_maps(model)
    name = model.name
    for a, b in links.items():
        la, lb = model.link(a), model.link(b)
        same_parents = (la.parent is None and lb.parent is None) or (
            la.parent is not None and lb.parent is not None and links[la.parent] == lb.parent)
        welded = (lb.parent == a and lb.joint is not None and lb.joint.at == (0.0, 0.0)) or (
            la.parent == b and la.joint is not None and la.joint.at == (0.0, 0.0))
        if not (same_parents or welded):
            raise SymmetryError(
                f"model {name!r}: symmetry pairs {a!r} with {b!r}, but their parents "
                f"{la.parent!r} and {lb.parent!r} are not a pair (nor is one the other's "
                "parent with the joint at its origin: a leg welded into it)")
        if la.direction != lb.direction or (
                same_parents and la.joint is not None and lb.joint is not None
                and la.joint.at != lb.joint.at):
            raise SymmetryError(
                f"model {name!r}: symmetry pairs {a!r} with {b!r}, but they differ in shape: "
                f"direction {la.direction!r} and {lb.direction!r}, joints at "
                f"{None if la.joint is None else la.joint.at} and "
                f"{None if lb.joint is None else lb.joint.at} on their parents")
    for a, b in contacts.items():
        if links[model.contact(a).link] != model.contact(b).link:
            raise SymmetryError(f"model {name!r}: symmetry pairs contacts {a!r} and {b!r}, "
                                "but their links are not a pair")
        if model.contact(a).at != model.contact(b).at:
            raise SymmetryError(f"model {name!r}: symmetry pairs contacts {a!r} and {b!r}, "
                                f"but they sit at {model.contact(a).at} and "
                                f"{model.contact(b).at} on their links")


def swap_matrices(model: RobotModel) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(S_q, S_u)``: the swap of the coordinates ``q' = S_q q`` (nq, nq; the same for
    ``qd``) and of the actuators ``u' = S_u u`` (nu, nu), both involutions (module
    docstring for the derivation). ``S_q`` keeps ``x, y``.

    Raises:
        SymmetryError: the swap does not map the model onto itself (:func:`_check_pairs`),
            or an actuator's permuted torques are no single actuator's (up to sign).
    """
    _check_pairs(model)
    t, p = chain_matrix(model), link_permutation(model)
    s_q = np.eye(model.nq)
    s_q[2:, 2:] = np.rint(np.linalg.solve(t, p @ t))  # integer entries: T, P are 0/1
    a = actuator_torques(model)
    s_u = np.zeros((model.nu, model.nu))
    for j, act in enumerate(model.actuators):
        target = p @ a[:, j]
        for k in range(model.nu):
            for sign in (1.0, -1.0):
                if np.array_equal(a[:, k], sign * target):
                    s_u[j, k] = sign
        if np.count_nonzero(s_u[j]) != 1:
            raise SymmetryError(f"model {model.name!r}: actuator {act.name!r} has no unique "
                                "counterpart on the other side (no actuator applies its "
                                "torques with the legs swapped)")
    return s_q, s_u


def swap_permutations(model: RobotModel) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Index permutations of ``q`` (nq,) and ``u`` (nu,) that exchange the legs
    (``q[perm_q] = S_q q``), for models whose swap is a permutation (every leg attached to
    the torso by its own hip).

    Raises:
        SymmetryError: as :func:`swap_matrices`, or the swap is no permutation (a leg welded
            into the base: use :func:`swap_matrices`).
    """
    s_q, s_u = swap_matrices(model)
    return _permutation(model, s_q, "q"), _permutation(model, s_u, "u")


def _permutation(model: RobotModel | None, s: NDArray[np.float64], what: str
                 ) -> NDArray[np.intp]:
    if not (np.all((s == 0.0) | (s == 1.0)) and np.all(s.sum(axis=1) == 1.0)):
        of = f"model {model.name!r}: " if model is not None else ""
        raise SymmetryError(f"{of}the leg swap of {what} is no permutation "
                            "(a leg welded into the base changes the base angle); use the "
                            "swap matrices")
    return np.argmax(s, axis=1).astype(np.intp)


def _apply(matrix: tuple[tuple[float, ...], ...], values: Sequence[Any]) -> list[Any]:
    """``matrix @ values`` on numbers or CasADi scalars, with only the nonzero terms (so a
    permutation gives back the values themselves)."""
    out: list[Any] = []
    for row in matrix:
        total: Any = None
        for coef, v in zip(row, values, strict=True):
            if coef == 0.0:
                continue
            term = v if coef == 1.0 else (-v if coef == -1.0 else coef * v)
            total = term if total is None else total + term
        out.append(0.0 if total is None else total)
    return out


@dataclass(frozen=True)
class LegSwap:
    """How the legs swap after a step: the maps of ``q`` and ``qd`` (``q_map``, (nq, nq))
    and of ``u`` (``u_map``, (nu, nu)) as nested tuples (hashable), and the contact names
    (every contact -> its counterpart, itself unless paired)."""

    q_map: tuple[tuple[float, ...], ...]
    u_map: tuple[tuple[float, ...], ...]
    contacts: Mapping[str, str]

    @property
    def s_q(self) -> NDArray[np.float64]:
        """``S_q`` (nq, nq) as an array."""
        return np.array(self.q_map, dtype=float)

    @property
    def s_u(self) -> NDArray[np.float64]:
        """``S_u`` (nu, nu) as an array (a signed permutation)."""
        return np.array(self.u_map, dtype=float).reshape(len(self.u_map), -1)

    @property
    def perm_q(self) -> tuple[int, ...]:
        """The permutation of ``q`` (``q[perm_q] = S_q q``) where the swap is one.

        Raises:
            SymmetryError: it is not (a leg welded into the base)."""
        return tuple(int(i) for i in _permutation(None, self.s_q, "q"))

    @property
    def perm_u(self) -> tuple[int, ...]:
        """The permutation of ``u`` (``u[perm_u] = S_u u``) where the swap is one (raises
        :class:`SymmetryError` otherwise, e.g. a welded leg's hip actuator: ``-u_hip``)."""
        return tuple(int(i) for i in _permutation(None, self.s_u, "u"))

    def swap_q(self, q: Sequence[Any]) -> list[Any]:
        """``S_q q`` (also for ``qd``) on a sequence of numbers or CasADi scalars."""
        return _apply(self.q_map, q)

    def swap_u(self, u: Sequence[Any]) -> list[Any]:
        """``S_u u`` on a sequence of numbers or CasADi scalars."""
        return _apply(self.u_map, u)

    def actuator_source(self, i: int) -> tuple[int, float]:
        """``(j, sign)`` with ``(S_u u)[i] = sign * u[j]``."""
        row = self.u_map[i]
        j = next(k for k, c in enumerate(row) if c != 0.0)
        return j, row[j]


@functools.lru_cache(maxsize=16)
def leg_swap(model: RobotModel) -> LegSwap:
    """The leg swap of ``model`` (declared in its file or inferred: :func:`model_symmetry`),
    built once per model.

    Raises:
        SymmetryError: as :func:`swap_matrices`.
    """
    s_q, s_u = swap_matrices(model)
    _, contacts = swap_maps(model)
    return LegSwap(tuple(tuple(float(c) for c in row) for row in s_q),
                   tuple(tuple(float(c) for c in row) for row in s_u), contacts)


def contact_pairing(model: RobotModel) -> dict[str, str]:
    """Every contact -> its counterpart on the other leg (itself unless paired): the
    contact pairs of the symmetry (declared, or inferred from the chains), or, for legs no
    symmetry pairs (unequal chains), the first two contact points (one per leg, as the
    built-in sequences take them). Needs no swap of the coordinates: a stride
    (:func:`gaitopt.gait.sequence.contact_sequence.stride_sequence`) only renames its points."""
    names = {c.name: c.name for c in model.contacts}
    try:
        return names | _mapping(model_symmetry(model).contacts)
    except SymmetryError:
        if len(model.contacts) < 2:
            raise
        c1, c2 = model.contacts[0].name, model.contacts[1].name
        return names | {c1: c2, c2: c1}


def identity_swap(model: RobotModel) -> LegSwap:
    """The map of a period that exchanges nothing (a stride's): identities of ``q``, ``u``
    and the contact names."""
    eye_q, eye_u = np.eye(model.nq), np.eye(model.nu)
    return LegSwap(tuple(tuple(float(c) for c in row) for row in eye_q),
                   tuple(tuple(float(c) for c in row) for row in eye_u),
                   {c.name: c.name for c in model.contacts})
