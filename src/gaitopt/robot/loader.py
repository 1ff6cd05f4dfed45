"""Reading, validating and writing model files (YAML, format ``gaitopt.model`` version 1).

The schema (every length in m, mass in kg, inertia in kg m^2, angle in rad, torque in N m)::

    format: gaitopt.model          # optional
    version: 1                     # optional; other major versions are rejected
    name: five-link
    description: free text         # optional
    gravity: [0.0, -9.81]          # optional, m/s^2, world frame
    links:                         # the floating base first (parent: null)
      - name: torso
        parent: null
        direction: up | down       # link axis in its own frame
        length: 0.72
        mass: 20.0
        com: [along, across]       # optional, default [length / 2, 0]; a number means [x, 0]
        inertia: 0.9               # about the centre of mass; or instead:
        shape: {type: ellipsoid, radius: 0.12}   # semi-axes length/2, r, r: m (a^2 + r^2) / 5
                                                 # or {type: rod}: m length^2 / 12
      - name: thigh_1
        parent: torso
        joint: {name: hip_1, at: [along, across] on the parent, limits: [lower, upper]}
        ...
    contacts:
      - {name: tip_1, link: shank_1, at: [along, across]}   # `at` defaults to [length, 0]
    actuators:                     # controls u, in this order
      - {name: hip_1, joint: hip_1, limits: [-150, 150]}
      - {name: ankle_1, contact: tip_1, limits: [-75, 75]}

Every error is a :class:`ModelError` naming the file, the field path, the bad value and what
is allowed.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from gaitopt.robot.model import Actuator, Contact, Joint, Link, RobotModel

FORMAT = "gaitopt.model"
VERSION = 1

_TOP_KEYS = {"format", "version", "name", "description", "gravity", "links", "contacts",
             "actuators"}
_LINK_KEYS = {"name", "parent", "joint", "direction", "length", "mass", "com", "inertia",
              "shape"}
_JOINT_KEYS = {"name", "at", "limits"}
_CONTACT_KEYS = {"name", "link", "at"}
_ACTUATOR_KEYS = {"name", "joint", "contact", "limits"}
_SHAPE_TYPES = ("ellipsoid", "rod")


class ModelError(ValueError):
    """A model file or description is invalid.

    Attributes:
        source: the file (or ``"<dict>"``) the model came from.
        path: the field path, e.g. ``links[2].mass``.
        value: the offending value.
        allowed: what would have been accepted.
    """

    def __init__(self, source: str, path: str, value: Any, allowed: str) -> None:
        self.source, self.path, self.value, self.allowed = source, path, value, allowed
        where = f"{path}: " if path else ""
        super().__init__(f"{source}: {where}{value!r} is invalid: {allowed}")


# -- public API ------------------------------------------------------------------------------

def builtin_names() -> list[str]:
    """Names of the models shipped with gaitopt."""
    folder = resources.files("gaitopt.robot") / "builtin"
    return sorted(p.name.removesuffix(".yaml") for p in folder.iterdir()
                  if p.name.endswith(".yaml"))


def builtin_text(name: str) -> str:
    """The YAML text of a built-in model."""
    if name not in builtin_names():
        raise ModelError("<builtin>", "", name,
                         f"a built-in model name, one of {', '.join(builtin_names())}")
    return (resources.files("gaitopt.robot") / "builtin" / f"{name}.yaml").read_text()


def load_model(name_or_path: str | os.PathLike[str]) -> RobotModel:
    """Load a built-in model by name (``five-link``) or a model file by path."""
    text_name = str(name_or_path)
    if text_name in builtin_names():
        return model_from_yaml(builtin_text(text_name), source=f"<builtin {text_name}>")
    path = Path(name_or_path)
    if not path.is_file():
        raise ModelError(str(path), "", text_name,
                         "an existing model file or a built-in model name "
                         f"({', '.join(builtin_names())})")
    return model_from_yaml(path.read_text(), source=str(path))


def model_from_yaml(text: str, *, source: str = "<string>") -> RobotModel:
    """Parse and validate YAML model text."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ModelError(source, where, "(YAML)", f"well-formed YAML ({exc})") from None
    return model_from_dict(data, source=source)


def model_from_dict(data: Any, *, source: str = "<dict>") -> RobotModel:
    """Validate plain data in the model-file schema and build a :class:`RobotModel`."""
    return _Validator(source).model(data)


def model_to_dict(model: RobotModel) -> dict[str, Any]:
    """The model as plain data in the model-file schema (inertia written explicitly)."""
    links: list[dict[str, Any]] = []
    for link in model.links:
        entry: dict[str, Any] = {"name": link.name, "parent": link.parent}
        if link.joint is not None:
            entry["joint"] = {"name": link.joint.name, "at": list(link.joint.at),
                              "limits": list(link.joint.limits)}
        entry.update({"direction": link.direction, "length": link.length, "mass": link.mass,
                      "com": list(link.com), "inertia": link.inertia})
        if link.shape is not None:
            entry["shape"] = dict(link.shape)
        links.append(entry)
    actuators: list[dict[str, Any]] = []
    for a in model.actuators:
        entry = {"name": a.name}
        entry["joint" if a.joint is not None else "contact"] = a.joint or a.contact
        entry["limits"] = list(a.limits)
        actuators.append(entry)
    return {
        "format": FORMAT, "version": VERSION, "name": model.name,
        "description": model.description, "gravity": list(model.gravity), "links": links,
        "contacts": [{"name": c.name, "link": c.link, "at": list(c.at)} for c in model.contacts],
        "actuators": actuators,
    }


def model_to_yaml(model: RobotModel) -> str:
    return yaml.safe_dump(model_to_dict(model), sort_keys=False, default_flow_style=None)


def ellipsoid_inertia(mass: float, length: float, radius: float) -> float:
    """Inertia (kg m^2) about the axis normal to the plane of a uniform ellipsoid with
    semi-axes ``length/2, radius, radius``: ``m ((length/2)^2 + radius^2) / 5``."""
    return mass * ((length / 2.0) ** 2 + radius**2) / 5.0


def rod_inertia(mass: float, length: float) -> float:
    """Inertia (kg m^2) of a thin uniform rod about its centre: ``m length^2 / 12``."""
    return mass * length**2 / 12.0


# -- validation ------------------------------------------------------------------------------

class _Validator:
    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, path: str, value: Any, allowed: str) -> ModelError:
        return ModelError(self.source, path, value, allowed)

    def mapping(self, path: str, value: Any, keys: set[str],
                required: tuple[str, ...] = ()) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.fail(path, value, "a mapping (key: value)")
        for key in value:
            if key not in keys:
                raise self.fail(f"{path}.{key}" if path else str(key), value[key],
                                f"unknown key; allowed keys are {', '.join(sorted(keys))}")
        for key in required:
            if key not in value:
                raise self.fail(path or "(top level)", f"missing {key!r}",
                                f"the key {key!r} is required")
        return value

    def number(self, path: str, value: Any, *, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(path, value, "a number" + (" > 0" if positive else ""))
        x = float(value)
        if not math.isfinite(x):
            raise self.fail(path, value, "a finite number")
        if positive and x <= 0.0:
            raise self.fail(path, value, "a number > 0")
        return x

    def name(self, path: str, value: Any) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.fail(path, value, "a non-empty string")
        return value

    def pair(self, path: str, value: Any) -> tuple[float, float]:
        if isinstance(value, int | float) and not isinstance(value, bool):
            return (self.number(path, value), 0.0)
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise self.fail(path, value, "a list of two numbers [along, across]")
        return (self.number(f"{path}[0]", value[0]), self.number(f"{path}[1]", value[1]))

    def bounds(self, path: str, value: Any) -> tuple[float, float]:
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise self.fail(path, value, "a list of two numbers [lower, upper]")
        lo = self.number(f"{path}[0]", value[0])
        hi = self.number(f"{path}[1]", value[1])
        if lo > hi:
            raise self.fail(path, list(value), "lower bound <= upper bound")
        return (lo, hi)

    def unique(self, path: str, name: str, seen: set[str], what: str) -> None:
        if name in seen:
            raise self.fail(path, name, f"a {what} name not used before")
        seen.add(name)

    def model(self, data: Any) -> RobotModel:
        top = self.mapping("", data, _TOP_KEYS, required=("name", "links"))
        if "format" in top and top["format"] != FORMAT:
            raise self.fail("format", top["format"], f"{FORMAT!r}")
        if "version" in top:
            version = top["version"]
            if isinstance(version, bool) or not isinstance(version, int) or version != VERSION:
                raise self.fail("version", version, f"major version {VERSION} (this gaitopt reads"
                                f" {FORMAT} version {VERSION} only)")
        name = self.name("name", top["name"])
        description = top.get("description") or ""
        if not isinstance(description, str):
            raise self.fail("description", description, "a string")
        gravity = (0.0, -9.81)
        if "gravity" in top:
            g = top["gravity"]
            if not isinstance(g, list | tuple) or len(g) != 2:
                raise self.fail("gravity", g, "a list of two numbers [gx, gy] in m/s^2")
            gravity = (self.number("gravity[0]", g[0]), self.number("gravity[1]", g[1]))
        links = self.links(top["links"])
        contacts = self.contacts(top.get("contacts") or [], links)
        actuators = self.actuators(top.get("actuators") or [], links, contacts)
        return RobotModel(name=name, links=links, contacts=contacts, actuators=actuators,
                          gravity=gravity, description=description.strip())

    def links(self, raw: Any) -> tuple[Link, ...]:
        if not isinstance(raw, list) or not raw:
            raise self.fail("links", raw, "a non-empty list of links")
        names: set[str] = set()
        joint_names: set[str] = set()
        entries = []
        for i, item in enumerate(raw):
            path = f"links[{i}]"
            entry = self.mapping(path, item, _LINK_KEYS,
                                 required=("name", "parent", "direction", "length", "mass"))
            self.unique(f"{path}.name", self.name(f"{path}.name", entry["name"]), names, "link")
            entries.append(entry)
        # Structure: one base, parents exist, no cycles, parents before children.
        parent_of = {e["name"]: e["parent"] for e in entries}
        bases = [i for i, e in enumerate(entries) if e["parent"] is None]
        if len(bases) != 1:
            raise self.fail("links", [entries[i]["name"] for i in bases],
                            "exactly one floating base link (parent: null)")
        if bases[0] != 0:
            raise self.fail(f"links[{bases[0]}].parent", None,
                            "the floating base (parent: null) must be the first link")
        for i, e in enumerate(entries):
            parent = e["parent"]
            if parent is not None and parent not in names:
                raise self.fail(f"links[{i}].parent", parent,
                                f"the name of a link in this model ({', '.join(sorted(names))})")
        for i, e in enumerate(entries):
            seen = [e["name"]]
            node = e["parent"]
            while node is not None:
                if node in seen:
                    raise self.fail(f"links[{i}].parent", e["parent"],
                                    "a parent that does not lead back to the link itself "
                                    f"(cycle {' -> '.join(seen + [node])})")
                seen.append(node)
                node = parent_of[node]
        order = {e["name"]: i for i, e in enumerate(entries)}
        for i, e in enumerate(entries):
            if e["parent"] is not None and order[e["parent"]] > i:
                raise self.fail(f"links[{i}].parent", e["parent"],
                                "a link listed before this one (parents come first)")
        return tuple(self.link(i, e, joint_names) for i, e in enumerate(entries))

    def link(self, i: int, e: Mapping[str, Any], joint_names: set[str]) -> Link:
        path = f"links[{i}]"
        direction = e["direction"]
        if direction not in ("up", "down"):
            raise self.fail(f"{path}.direction", direction, "'up' or 'down'")
        length = self.number(f"{path}.length", e["length"], positive=True)
        mass = self.number(f"{path}.mass", e["mass"], positive=True)
        com = self.pair(f"{path}.com", e["com"]) if "com" in e else (length / 2.0, 0.0)
        joint = None
        if e["parent"] is None:
            if "joint" in e and e["joint"] is not None:
                raise self.fail(f"{path}.joint", e["joint"],
                                "no joint on the floating base (parent: null)")
        else:
            if "joint" not in e:
                raise self.fail(path, "missing 'joint'", "a joint for every non-base link")
            jpath = f"{path}.joint"
            j = self.mapping(jpath, e["joint"], _JOINT_KEYS, required=("name", "limits"))
            jname = self.name(f"{jpath}.name", j["name"])
            self.unique(f"{jpath}.name", jname, joint_names, "joint")
            at = self.pair(f"{jpath}.at", j["at"]) if "at" in j else (0.0, 0.0)
            joint = Joint(name=jname, at=at, limits=self.bounds(f"{jpath}.limits", j["limits"]))
        shape = None
        if "inertia" in e and "shape" in e:
            raise self.fail(f"{path}.shape", e["shape"],
                            "either 'inertia' or 'shape', not both")
        if "inertia" in e:
            inertia = self.number(f"{path}.inertia", e["inertia"], positive=True)
        elif "shape" in e:
            spath = f"{path}.shape"
            s = e["shape"]
            if not isinstance(s, Mapping) or s.get("type") not in _SHAPE_TYPES:
                raise self.fail(f"{spath}.type", s.get("type") if isinstance(s, Mapping) else s,
                                f"a shape type, one of {', '.join(_SHAPE_TYPES)}")
            if s["type"] == "ellipsoid":
                self.mapping(spath, s, {"type", "radius"}, required=("radius",))
                radius = self.number(f"{spath}.radius", s["radius"], positive=True)
                inertia = ellipsoid_inertia(mass, length, radius)
                shape = {"type": "ellipsoid", "radius": radius}
            else:
                self.mapping(spath, s, {"type"})
                inertia = rod_inertia(mass, length)
                shape = {"type": "rod"}
        else:
            raise self.fail(path, "missing 'inertia' and 'shape'",
                            "an 'inertia' (kg m^2, > 0) or a 'shape' to compute it from")
        return Link(name=e["name"], parent=e["parent"], joint=joint, direction=direction,
                    length=length, mass=mass, com=com, inertia=inertia, shape=shape)

    def contacts(self, raw: Any, links: tuple[Link, ...]) -> tuple[Contact, ...]:
        if not isinstance(raw, list):
            raise self.fail("contacts", raw, "a list of contact points")
        by_name = {link.name: link for link in links}
        names: set[str] = set()
        out = []
        for i, item in enumerate(raw):
            path = f"contacts[{i}]"
            c = self.mapping(path, item, _CONTACT_KEYS, required=("name", "link"))
            name = self.name(f"{path}.name", c["name"])
            self.unique(f"{path}.name", name, names, "contact")
            link = c["link"]
            if link not in by_name:
                raise self.fail(f"{path}.link", link,
                                f"the name of a link in this model ({', '.join(by_name)})")
            at = self.pair(f"{path}.at", c["at"]) if "at" in c else (by_name[link].length, 0.0)
            out.append(Contact(name=name, link=link, at=at))
        return tuple(out)

    def actuators(self, raw: Any, links: tuple[Link, ...],
                  contacts: tuple[Contact, ...]) -> tuple[Actuator, ...]:
        if not isinstance(raw, list):
            raise self.fail("actuators", raw, "a list of actuators")
        joints = [link.joint.name for link in links if link.joint is not None]
        contact_names = [c.name for c in contacts]
        names: set[str] = set()
        out = []
        for i, item in enumerate(raw):
            path = f"actuators[{i}]"
            a = self.mapping(path, item, _ACTUATOR_KEYS, required=("name", "limits"))
            name = self.name(f"{path}.name", a["name"])
            self.unique(f"{path}.name", name, names, "actuator")
            if ("joint" in a) == ("contact" in a):
                raise self.fail(path, {k: a[k] for k in ("joint", "contact") if k in a},
                                "exactly one of 'joint' (a joint torque) or 'contact' "
                                "(a torque at a contact point, e.g. an ankle)")
            if "joint" in a and a["joint"] not in joints:
                raise self.fail(f"{path}.joint", a["joint"],
                                f"the name of a joint in this model ({', '.join(joints)})")
            if "contact" in a and a["contact"] not in contact_names:
                raise self.fail(f"{path}.contact", a["contact"],
                                "the name of a contact point in this model "
                                f"({', '.join(contact_names) or 'none defined'})")
            out.append(Actuator(name=name, limits=self.bounds(f"{path}.limits", a["limits"]),
                                joint=a.get("joint"), contact=a.get("contact")))
        return tuple(out)
