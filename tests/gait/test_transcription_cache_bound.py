"""The process-wide transcription cache keeps at most ``MAX_LARGE_EXPANDED`` large expanded
transcriptions (the compressed form's, whose exact Hessian of the whole mesh takes gigabytes
on fine grids), the least recently used going first; point-wise ones are all kept."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from gaitopt.gait import transcriptions as tc
from gaitopt.gait.options import GaitOptions
from gaitopt.robot import load_model

PAPER = GaitOptions.paper()
#: Three structures of the compressed form (another NLP each), on the paper's small grid.
VARIANTS = [PAPER, PAPER.replace(ankle=False), PAPER.replace(impulse=False)]


@pytest.fixture
def bounded(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Every expanded transcription counts as large; at most two are kept."""
    monkeypatch.setattr(tc, "LARGE_EXPANDED", 0)
    monkeypatch.setattr(tc, "MAX_LARGE_EXPANDED", 2)
    tc.clear_cache()
    yield
    tc.clear_cache()


def _cached() -> list[object]:
    return list(tc._CACHE.values())


@pytest.mark.usefixtures("bounded")
def test_the_least_recently_used_large_expanded_transcription_goes_first() -> None:
    model = load_model("five-link")
    a, b = (tc.transcription_for(model, o, o.knots) for o in VARIANTS[:2])
    assert tc.transcription_for(model, VARIANTS[0], PAPER.knots) is a  # a used again
    c = tc.transcription_for(model, VARIANTS[2], PAPER.knots)
    kept = _cached()
    assert a in kept and c in kept and b not in kept
    # b is built again when asked for (a new object), which drops a, now the oldest
    again = tc.transcription_for(model, VARIANTS[1], PAPER.knots)
    assert again is not b and again.layout.size == b.layout.size
    assert set(map(id, _cached())) == {id(c), id(again)}


@pytest.mark.usefixtures("bounded")
def test_point_wise_transcriptions_are_all_kept() -> None:
    model = load_model("five-link")
    separated = GaitOptions(knots=(8, 5), knot_spacing="uniform")
    points = [tc.transcription_for(model, separated.replace(ankle=ankle, impulse=impulse),
                                   (8, 5))
              for ankle in (True, False) for impulse in (True, False)]
    expanded = [tc.transcription_for(model, o, o.knots) for o in VARIANTS]
    kept = _cached()
    assert all(tr in kept for tr in points)
    assert [tr in kept for tr in expanded] == [False, True, True]
