"""The summary's "friction needed": the largest |tangential| / normal of the contact forces
at the knots and of the events' impulses on held tips, where it is, and, for a frictionless
solve whose ratio no ground could offer, the forces behind it and how to bound them."""

from __future__ import annotations

import numpy as np
import pytest

from gaitopt.analysis.metrics import NORMAL_FLOOR, gait_metrics
from gaitopt.cli.gait_summary import FRICTION_SHOWN, friction_text
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from tests.gait.conftest import SolveFn


def _pairs(gait: Gait) -> list[tuple[float, float]]:
    """Every (tangential, normal) force at a knot and impulse at an event in the file."""
    out = [(float(t), float(n)) for ph in gait.phases for f in ph.contact_forces.values()
           for t, n in f]
    return out + [(float(i[0]), float(i[1])) for e in gait.events for i in e.impulses.values()]


def test_the_place_and_forces_of_the_largest_ratio(default_gait: Gait) -> None:
    m = gait_metrics(default_gait)
    pair = (m.friction_tangential, m.friction_normal)
    assert pair in _pairs(default_gait)  # a force or impulse of the file, not a made-up one
    assert abs(pair[0]) / max(pair[1], NORMAL_FLOOR) == pytest.approx(m.friction_required)
    contact, place = m.friction_where.split(", ")
    assert contact in [c.name for c in default_gait.model.contacts]
    assert place.endswith(" impulse") or " of " in place


def test_a_frictionless_gait_says_why_its_ratio_is_huge(default_gait: Gait) -> None:
    """The paper's gait (no friction limit): the trailing tip's heel-strike impulse is almost
    tangential (its normal part about 0), a ratio no ground offers."""
    m = gait_metrics(default_gait)
    assert m.friction_required > FRICTION_SHOWN
    text = friction_text(m, default_gait.options.get("friction"))
    assert m.friction_where in text and "sideways against a normal" in text
    assert "--friction MU" in text


def test_a_gait_within_a_friction_cone_shows_its_ratio(solved: SolveFn) -> None:
    gait = solved(GaitOptions.paper(friction=0.3)).gait
    m = gait_metrics(gait)
    assert m.friction_required <= 0.3 * (1 + 1e-3)
    text = friction_text(m, 0.3)
    assert text == f"{m.friction_required:.3f} (|tangential|/normal at {m.friction_where})"
    assert np.isfinite(m.friction_tangential) and m.friction_normal > 0
