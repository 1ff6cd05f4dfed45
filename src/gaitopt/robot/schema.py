"""The model-file schema (format ``gaitopt.model``, version 1): validation of plain data into a
:class:`~gaitopt.robot.model.RobotModel`, and the model back to plain data.

Plain data is what YAML or JSON parse into: mappings, lists, strings, numbers and null. Units:
lengths in m, masses in kg, inertias in kg m^2 (about the centre of mass, about z), angles in
rad, torques in N m, gravity in m/s^2. Points on a link are ``[along, across]`` (see
:mod:`gaitopt.robot.model`). The full schema with every field and default is in
``docs/conventions.md``; in short::

    format: gaitopt.model     # optional; version: 1 (optional; other versions are rejected)
    name: five-link
    description: free text    # optional
    gravity: [0.0, -9.81]     # optional
    links:                    # the floating base first (parent: null), parents before children
      - {name, parent, direction: up|down, length, mass, com (default [length/2, 0]),
         inertia and/or shape: {type: ellipsoid, radius} | {type: rod},
         joint: {name, at: [along, across] on the parent, limits: [lower, upper],
                 damping: b}}  # not base; damping optional (N m s/rad, default 0)
    contacts:                 # optional
      - {name, link, at (default [length, 0]: the link's far end)}
    actuators:                # optional; the controls u, in this order
      - {name, joint: NAME | contact: NAME, limits: [lower, upper]}

Joint limits may be ``null`` (no bound: ``-inf`` or ``inf`` in the model). Masses and inertias
may be 0 (point masses, massless frames) as long as the model's mass matrix is positive
definite (:mod:`gaitopt.robot.mass_matrix`, checked last).

Every problem raises :class:`ModelError`, which names the source (file), the field path, the
bad value and what is allowed. Validation never raises any other exception, whatever the data.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from gaitopt.robot.errors import MISSING, ModelError, show_value
from gaitopt.robot.fields import FieldReader, names_text
from gaitopt.robot.inertia import INERTIA_RTOL, shape_inertia
from gaitopt.robot.mass_matrix import check_positive_definite
from gaitopt.robot.model import (
    FORMAT,
    VERSION,
    Actuator,
    Contact,
    Direction,
    Joint,
    Link,
    RobotModel,
    Shape,
    SymmetrySpec,
)
from gaitopt.robot.symmetry import SymmetryError, swap_matrices

DEFAULT_GRAVITY: tuple[float, float] = (0.0, -9.81)

TOP_KEYS = ("format", "version", "name", "description", "gravity", "links", "contacts",
            "actuators", "symmetry")
SYMMETRY_KEYS = ("links", "contacts")
LINK_KEYS = ("name", "parent", "joint", "direction", "length", "mass", "com", "inertia", "shape")
JOINT_KEYS = ("name", "at", "limits", "damping")
JOINT_REQUIRED = ("name", "at", "limits")
CONTACT_KEYS = ("name", "link", "at")
ACTUATOR_KEYS = ("name", "joint", "contact", "limits")
SHAPE_TYPES = ("ellipsoid", "rod")
DIRECTIONS = ("up", "down")


# -- plain data -> model ---------------------------------------------------------------------

def model_from_dict(data: Any, *, source: str = "<dict>") -> RobotModel:
    """Validate plain data in the model-file schema and build a :class:`RobotModel`.

    Raises:
        ModelError: for any problem, naming ``source``, the field path, the value and what is
            allowed. No other exception escapes, whatever ``data`` is.
    """
    return _Validator(source).model(data)


class _Validator(FieldReader):
    """Checks one model description; ``source`` goes into every error."""

    # -- the model ---------------------------------------------------------------------------
    def model(self, data: Any) -> RobotModel:
        if data is None:
            raise self.fail("", None, "a model: a mapping with at least 'name' and 'links'",
                            problem="empty model (no YAML content)")
        top = self.mapping("", data, TOP_KEYS, ("name", "links"), "a model")
        if "format" in top and (not isinstance(top["format"], str) or top["format"] != FORMAT):
            raise self.fail("format", top["format"], f"{FORMAT!r}")
        if "version" in top:
            version = top["version"]
            if isinstance(version, bool) or not isinstance(version, int) or version != VERSION:
                raise self.fail("version", version,
                                f"{VERSION} (this gaitopt reads {FORMAT} version {VERSION} only)")
        name = self.name("name", top["name"])
        description = top.get("description")
        if description is None:
            description = ""
        if not isinstance(description, str) or not all(
                c.isprintable() or c in "\n\t" for c in description):
            raise self.fail("description", description,
                            "a text of printable characters, new lines and tabs (or null)")
        gravity = DEFAULT_GRAVITY
        if "gravity" in top:
            gravity = self.pair("gravity", top["gravity"], "[gx, gy] in m/s^2, world frame")
        links = self.links(top["links"])
        contacts = self.contacts(self.optional_list("contacts", top.get("contacts"),
                                                    "contact points"), links)
        actuators = self.actuators(self.optional_list("actuators", top.get("actuators"),
                                                      "actuators"), links, contacts)
        symmetry = (self.symmetry(top["symmetry"], links, contacts)
                    if top.get("symmetry") is not None else None)
        model = RobotModel(name=name, links=links, contacts=contacts, actuators=actuators,
                           gravity=gravity, description=description, symmetry=symmetry)
        check_positive_definite(model, source=self.source)
        if symmetry is not None:
            try:
                swap_matrices(model)
            except SymmetryError as exc:
                raise self.fail("symmetry", top["symmetry"],
                                "pairs that map the model onto itself", problem=str(exc)
                                ) from None
        return model

    def symmetry(self, raw: Any, links: tuple[Link, ...],
                 contacts: tuple[Contact, ...]) -> SymmetrySpec:
        """``{links: [[a, b], ...], contacts: [[c, d], ...]}``: disjoint pairs of names."""
        top = self.mapping("symmetry", raw, SYMMETRY_KEYS, ("contacts",),
                           "the left/right symmetry (pairs of links and of contacts)")
        seen: set[str] = set()
        out: dict[str, tuple[tuple[str, str], ...]] = {}
        for key, known in (("links", [link.name for link in links]),
                           ("contacts", [c.name for c in contacts])):
            pairs = []
            for i, item in enumerate(self.optional_list(f"symmetry.{key}", top.get(key), key)):
                path = f"symmetry.{key}[{i}]"
                if (not isinstance(item, list) or len(item) != 2
                        or not all(isinstance(n, str) and n in known for n in item)
                        or item[0] == item[1]):
                    raise self.fail(path, item, f"a pair [left, right] of two different "
                                                f"{key} of this model ({names_text(known)})")
                for n in item:
                    if n in seen:
                        raise self.fail(path, item, "each name in one pair at most",
                                        problem=f"{n!r} is already paired")
                    seen.add(n)
                pairs.append((item[0], item[1]))
            out[key] = tuple(pairs)
        return SymmetrySpec(links=out["links"], contacts=out["contacts"])

    def links(self, raw: Any) -> tuple[Link, ...]:
        if not isinstance(raw, list) or not raw:
            raise self.fail("links", raw, "a non-empty list of links, the floating base first")
        names: set[str] = set()
        entries: list[Mapping[str, Any]] = []
        parents: list[str | None] = []
        for i, item in enumerate(raw):
            path = f"links[{i}]"
            e = self.mapping(path, item, LINK_KEYS,
                             ("name", "parent", "direction", "length", "mass"), "a link")
            self.unique(f"{path}.name", self.name(f"{path}.name", e["name"]), names, "link")
            parent = e["parent"]
            if parent is not None:
                parent = self.name(f"{path}.parent", parent)
            entries.append(e)
            parents.append(parent)
        self.tree(names, [e["name"] for e in entries], parents)
        base_name = entries[0]["name"]
        if base_name in ("x", "y"):
            raise self.fail("links[0].name", base_name,
                            "a name other than x and y (the base link's name names its angle "
                            "in q = [x, y, <base>, ...])")
        joint_names: set[str] = set()
        return tuple(self.link(i, e, parents[i], joint_names, base_name)
                     for i, e in enumerate(entries))

    def tree(self, names: set[str], order: list[str], parents: list[str | None]) -> None:
        """One base, first; every parent exists; no cycle; parents before their children."""
        bases = [n for n, p in zip(order, parents, strict=True) if p is None]
        if len(bases) != 1:
            raise self.fail("links", bases, "exactly one floating base link (parent: null)",
                            problem=f"{len(bases)} links with parent null {show_value(bases)}")
        if parents[0] is not None:
            i = order.index(bases[0])
            raise self.fail(f"links[{i}].parent", None,
                            "the floating base (parent: null) as the first link",
                            problem=f"the floating base {bases[0]!r} is link {i}, not link 0")
        for i, parent in enumerate(parents):
            if parent is not None and parent not in names:
                raise self.fail(f"links[{i}].parent", parent,
                                f"the name of a link in this model ({names_text(names)})")
        parent_of = dict(zip(order, parents, strict=True))
        for i, start in enumerate(order):
            seen = [start]
            node = parent_of[start]
            while node is not None:
                if node in seen:
                    cycle = " -> ".join([*seen[seen.index(node):], node])
                    raise self.fail(f"links[{i}].parent", parent_of[start],
                                    "parents that lead to the floating base (a tree)",
                                    problem=f"a cycle of parents {cycle} "
                                            f"(parent {parent_of[start]!r})")
                seen.append(node)
                node = parent_of[node]
        position = {n: i for i, n in enumerate(order)}
        for i, parent in enumerate(parents):
            if parent is not None and position[parent] > i:
                raise self.fail(f"links[{i}].parent", parent,
                                f"a link listed before links[{i}] (parents come first)")

    def link(self, i: int, e: Mapping[str, Any], parent: str | None, joint_names: set[str],
             base_name: str) -> Link:
        path = f"links[{i}]"
        direction: Direction
        raw_direction = e["direction"] if isinstance(e["direction"], str) else None
        if raw_direction == "up":
            direction = "up"
        elif raw_direction == "down":
            direction = "down"
        else:
            raise self.fail(f"{path}.direction", e["direction"],
                            "'up' or 'down' (the link axis in its own frame)")
        length = self.number(f"{path}.length", e["length"], "a number > 0 (m)", positive=True)
        mass = self.number(f"{path}.mass", e["mass"], "a number >= 0 (kg)", nonnegative=True)
        com = (self.pair(f"{path}.com", e["com"], "[along, across] in m")
               if "com" in e else (length / 2.0, 0.0))
        joint = None
        if parent is None:
            if e.get("joint") is not None:
                raise self.fail(f"{path}.joint", e["joint"],
                                "no joint (or null) on the floating base (parent: null)")
        else:
            joint = self.joint(f"{path}.joint", e.get("joint", MISSING), joint_names, base_name)
        shape = self.shape(f"{path}.shape", e["shape"]) if "shape" in e else None
        if "inertia" in e:
            inertia = self.number(f"{path}.inertia", e["inertia"],
                                  "a number >= 0 (kg m^2, about the centre of mass; 0 for a "
                                  "point mass)", nonnegative=True)
            if shape is not None:
                expected = shape_inertia(shape, mass, length)
                if abs(inertia - expected) > INERTIA_RTOL * expected:
                    raise self.fail(f"{path}.inertia", e["inertia"],
                                    f"the inertia of the shape, {expected!r} kg m^2 (or give "
                                    "only one of 'inertia' and 'shape')")
        elif shape is not None:
            inertia = shape_inertia(shape, mass, length)
            if not (math.isfinite(inertia) and inertia >= 0.0):
                raise self.fail(f"{path}.shape", e["shape"],
                                "a shape whose inertia (with this mass and length) is a finite "
                                f"number >= 0 kg m^2, not {inertia!r}")
        else:
            raise self.fail(f"{path}.inertia", MISSING,
                            "an 'inertia' (kg m^2, >= 0) or a 'shape' to compute it from")
        return Link(name=e["name"], parent=parent, joint=joint, direction=direction,
                    length=length, mass=mass, com=com, inertia=inertia, shape=shape)

    def joint(self, path: str, raw: Any, joint_names: set[str], base_name: str) -> Joint:
        if raw is MISSING:
            raise self.fail(path, MISSING, "a joint {name, at, limits} on every link but the "
                            "floating base")
        j = self.mapping(path, raw, JOINT_KEYS, JOINT_REQUIRED, "a joint")
        name = self.name(f"{path}.name", j["name"])
        reserved = {"x", "y", base_name}
        if name in reserved:
            raise self.fail(f"{path}.name", name,
                            f"a name other than {names_text(reserved)} (they name the base "
                            "coordinates of q)")
        self.unique(f"{path}.name", name, joint_names, "joint")
        at = self.pair(f"{path}.at", j["at"], "[along, across] in m on the parent link")
        damping = (self.number(f"{path}.damping", j["damping"], "a number >= 0 (N m s/rad)",
                               nonnegative=True) if "damping" in j else 0.0)
        return Joint(name=name, at=at, limits=self.bounds(f"{path}.limits", j["limits"], "rad",
                                                          unbounded=True), damping=damping)

    def shape(self, path: str, raw: Any) -> Shape:
        if not isinstance(raw, Mapping) or "type" not in raw:
            raise self.fail(path, raw, "{type: ellipsoid, radius: R} or {type: rod}")
        kind = raw["type"] if isinstance(raw["type"], str) else None
        if kind == "ellipsoid":
            s = self.mapping(path, raw, ("type", "radius"), ("type", "radius"), "an ellipsoid")
            radius = self.number(f"{path}.radius", s["radius"], "a number > 0 (m)",
                                 positive=True)
            return Shape(type="ellipsoid", radius=radius)
        if kind == "rod":
            self.mapping(path, raw, ("type",), ("type",), "a rod")
            return Shape(type="rod")
        raise self.fail(f"{path}.type", raw["type"],
                        f"a shape type, one of {', '.join(SHAPE_TYPES)}")

    def contacts(self, raw: list[Any], links: tuple[Link, ...]) -> tuple[Contact, ...]:
        by_name = {link.name: link for link in links}
        names: set[str] = set()
        out = []
        for i, item in enumerate(raw):
            path = f"contacts[{i}]"
            c = self.mapping(path, item, CONTACT_KEYS, ("name", "link"), "a contact point")
            name = self.name(f"{path}.name", c["name"])
            self.unique(f"{path}.name", name, names, "contact")
            link = c["link"]
            if not isinstance(link, str) or link not in by_name:
                raise self.fail(f"{path}.link", link,
                                f"the name of a link in this model ({names_text(list(by_name))})")
            at = (self.pair(f"{path}.at", c["at"], "[along, across] in m on the link")
                  if "at" in c else (by_name[link].length, 0.0))
            out.append(Contact(name=name, link=link, at=at))
        return tuple(out)

    def actuators(self, raw: list[Any], links: tuple[Link, ...],
                  contacts: tuple[Contact, ...]) -> tuple[Actuator, ...]:
        joints = [link.joint.name for link in links if link.joint is not None]
        contact_names = [c.name for c in contacts]
        names: set[str] = set()
        driven: dict[str, str] = {}
        out = []
        for i, item in enumerate(raw):
            path = f"actuators[{i}]"
            a = self.mapping(path, item, ACTUATOR_KEYS, ("name", "limits"), "an actuator")
            name = self.name(f"{path}.name", a["name"])
            self.unique(f"{path}.name", name, names, "actuator")
            if ("joint" in a) == ("contact" in a):
                raise self.fail(path, {k: a[k] for k in ("joint", "contact") if k in a},
                                "exactly one of 'joint' (a joint torque) or 'contact' "
                                "(a torque between the ground and the link at a contact "
                                "point, e.g. an ankle)")
            kind, known = ("joint", joints) if "joint" in a else ("contact", contact_names)
            target = a[kind]
            if not isinstance(target, str) or target not in known:
                raise self.fail(f"{path}.{kind}", target,
                                f"the name of a {kind} in this model ({names_text(known)})")
            key = f"{kind} {target}"
            if key in driven:
                raise self.fail(f"{path}.{kind}", target,
                                f"a {kind} that no other actuator drives",
                                problem=f"{kind} {target!r} is already driven by actuator "
                                        f"{driven[key]!r}")
            driven[key] = name
            limits = self.bounds(f"{path}.limits", a["limits"], "N m")
            out.append(Actuator(name=name, limits=limits, joint=target if kind == "joint"
                                else None, contact=target if kind == "contact" else None))
        return tuple(out)


__all__ = ["DEFAULT_GRAVITY", "FORMAT", "VERSION", "ModelError", "model_from_dict"]
