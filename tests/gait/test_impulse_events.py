"""The events that apply the liftoff impulse are those the gait file's contact sequence marks
(``impulse``), whatever they are called: the walk's ``liftoff``, the heel-toe walk's
``toe_off`` (:func:`gaitopt.gait.formulations.cost.impulse_events`); only a file without a sequence
is read by the name ``liftoff``. The recomputed cost charges their work, the parameter check
compares their impulse with ``liftoff_impulse``, and the friction check exempts their lifting tip.

The gaits are the default five-link walk with its ``liftoff`` given a chosen impulse through
the liftoff map and renamed: renaming changes no physics, so every result must stay the same.
Recognising the event by the name ``liftoff`` alone dropped the impulse's work from the
heel-toe walks' recomputed cost (``cost.recomputed`` 2.2e-5 on the seven-link 0 W/kg
metabolic optimum).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from numpy.typing import NDArray

from gaitopt.analysis.metrics import gait_metrics
from gaitopt.analysis.verify import verify_gait
from gaitopt.dynamics.functions import liftoff_function
from gaitopt.gait.formulations import cost
from gaitopt.gait.formulations.full.physics import per_point
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from tests.gait.conftest import Reference

Array = NDArray[np.float64]

#: (event name, the file keeps its contact sequence): the walk's name, the heel-toe walk's
#: name, and a file without a sequence.
NAMINGS = [("liftoff", True), ("toe_off", True), ("liftoff", False)]


def _with_impulse(gait: Gait, magnitude: float, name: str, *, sequence: bool,
                  lifting: tuple[float, float] | None = None,
                  **options: object) -> tuple[Gait, Array, Array, Array]:
    """The gait (``options`` changed) whose liftoff applies the impulse ``magnitude`` (N s),
    ``qd_after`` and the impulses by the liftoff map from ``qd_before`` (the lifting tip's
    impulse replaced by ``lifting`` if given), the event renamed ``name`` in the events and the
    contact sequence (``sequence=False`` drops the sequence, as in a file written before gait
    files had one); and the event's ``q``, ``qd_before`` and ``qd_after`` (nq,)."""
    data = gait.to_dict()
    data["options"].update(options)
    data["parameters"]["liftoff_impulse"] = magnitude
    i = next(j for j, e in enumerate(gait.events) if e.name == "liftoff")
    event = gait.events[i]
    phase = next(ph for ph in gait.phases if ph.t[-1] == event.t)
    held = tuple(c for c in phase.contacts if c != event.leg)
    qd, push, on_held = (np.asarray(v, dtype=float).ravel() for v in liftoff_function(
        gait.model, event.leg, held)(phase.q[-1], event.qd_before, magnitude))
    impulses = {event.leg: list(lifting) if lifting is not None else push.tolist()}
    impulses |= {c: np.asarray(v, dtype=float).ravel().tolist()
                 for c, v in per_point(held, on_held).items()}
    data["events"][i].update(name=name, qd_after=qd.tolist(), impulses=impulses)
    if sequence:
        assert data["contact_sequence"]["events"][i]["impulse"]
        data["contact_sequence"]["events"][i]["name"] = name
    else:
        del data["contact_sequence"]
    return Gait.from_dict(data), phase.q[-1], event.qd_before, qd


@pytest.mark.parametrize(("name", "sequence"), NAMINGS)
def test_the_cost_charges_the_impulse_work_whatever_the_event_is_called(
        default_gait: Gait, reference: Callable[..., Reference], name: str,
        sequence: bool) -> None:
    """The costs of transport charge the liftoff impulse's work ``E_P / eta_pos``. With the
    lifting tip at rest before and the held tip at rest throughout, ``E_P`` is the kinetic
    energy the event adds, ``(qd+' M qd+ - qd-' M qd-) / 2`` with Pinocchio's mass matrix."""
    base, *_ = _with_impulse(default_gait, 0.0, name, sequence=sequence, cost="metabolic")
    pushed, q, qd_before, qd_after = _with_impulse(default_gait, 2.0, name, sequence=sequence,
                                                   cost="metabolic")
    m = reference(default_gait.model).mass_matrix(q)
    kinetic = 0.5 * (qd_after @ m @ qd_after - qd_before @ m @ qd_before)
    assert kinetic > 0.01  # the impulse does work that the cost must see
    model, options = default_gait.model, GaitOptions.paper(cost="metabolic")
    expected = kinetic / options.efficiency_positive / (cost.weight(model)
                                                       * default_gait.step_length)
    assert cost.recompute_cost(pushed) - cost.recompute_cost(base) == pytest.approx(
        expected, rel=1e-7)


@pytest.mark.parametrize(("name", "sequence"), NAMINGS)
def test_the_parameter_check_compares_the_impulse_whatever_the_event_is_called(
        default_gait: Gait, name: str, sequence: bool) -> None:
    """The impulse of 2 N s on the lifting tip agrees with ``liftoff_impulse = 2`` and is
    caught when the parameter says 1."""
    pushed, *_ = _with_impulse(default_gait, 2.0, name, sequence=sequence)
    assert verify_gait(pushed).check("parameters.consistency").passed
    data = pushed.to_dict()
    data["parameters"]["liftoff_impulse"] = 1.0
    check = verify_gait(Gait.from_dict(data)).check("parameters.consistency")
    assert not check.passed and check.where == "parameters.liftoff_impulse"


@pytest.mark.parametrize(("name", "sequence"), NAMINGS)
def test_the_lifting_tip_is_exempt_from_friction_whatever_the_event_is_called(
        default_gait: Gait, name: str, sequence: bool) -> None:
    """The NLP bounds by friction only the impulses on tips held after an event; the lifting
    tip's push (here a horizontal 1000 N s, far beyond any knot's excess) changes nothing."""
    values = [verify_gait(_with_impulse(default_gait, 2.0, name, sequence=sequence,
                                        lifting=lifting, friction=1.0)[0]
                          ).check("contacts.friction").value
              for lifting in ((0.0, 0.0), (1000.0, 0.0))]
    assert values[1] == values[0] < 1000.0


@pytest.mark.parametrize(("name", "sequence"), NAMINGS)
def test_the_summary_leaves_out_the_lifting_push_whatever_the_event_is_called(
        default_gait: Gait, name: str, sequence: bool) -> None:
    """The summary's smallest normal impulse and friction needed are of the tips held on the
    ground: a horizontal 1000 N s push of the lifting tip, or one pulling it into the ground,
    changes neither."""
    metrics = [gait_metrics(_with_impulse(default_gait, 2.0, name, sequence=sequence,
                                          lifting=lifting)[0])
               for lifting in ((0.0, 0.0), (1000.0, -5.0))]
    assert metrics[1].friction_required == metrics[0].friction_required
    assert metrics[1].min_normal_impulse == metrics[0].min_normal_impulse > -5.0
