"""Contact points of the MJCF import: from ``--contact NAME=BODY:X,Z`` or inferred from the
foot geoms (the leaf links' capsules, spheres, boxes and cylinders as planar shapes)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from gaitopt.robot.urdf import ContactSpec

if TYPE_CHECKING:
    from gaitopt.robot.mjcf_build import Builder, Link, Vec


def contact_points(builder: Builder, links: list[Link], link_of: dict[int, int],
                   specs: list[ContactSpec]) -> list[tuple[str, int, Vec]]:
    """``(name, link index, gaitopt (x, y) relative to the link origin)`` per contact point:
    the ``specs`` when given (a point ``(X, Z)`` m in MuJoCo body BODY's frame), else none."""
    if not specs:
        builder.notes.append("contacts: none (give them with --contact NAME=BODY:X,Z)")
        return []
    m, d, mj = builder.m, builder.d, builder.mj
    out: list[tuple[str, int, Vec]] = []
    for spec in specs:
        if spec.name in {c[0] for c in out}:
            raise builder.fail(f"contact {spec.name!r}", spec.name, "a contact name not used "
                               "by another contact", problem="a duplicate contact name")
        b = mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, spec.link)
        if b not in link_of:
            names = ", ".join(builder.name("body", i) for i in link_of)
            raise builder.fail(f"contact {spec.name!r}", spec.link, f"the name of a body of the "
                               f"robot ({names})", problem=f"no body {spec.link!r}")
        local = np.zeros(3)
        local[builder.in_plane[0]], local[builder.in_plane[1]] = spec.point
        world = d.xpos[b] + d.xmat[b].reshape(3, 3) @ local
        k = link_of[b]
        out.append((spec.name, k, builder.xy(world - links[k].origin)))
    builder.notes.append("contacts: from --contact: " + ", ".join(
        f"{s.name} on {s.link}" for s in specs))
    return out
