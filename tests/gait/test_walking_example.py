"""examples/walking.py runs end to end and writes what it says."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from gaitopt import Gait

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "walking.py"


def test_walking_example(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("walking_example", EXAMPLE)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    gait = module.main(["--out", str(tmp_path), "--speed", "12", "--animate"])
    out = capsys.readouterr().out
    assert "verify: passed" in out
    saved = Gait.load(tmp_path / "walk.gait.json")
    np.testing.assert_array_equal(saved.phases[0].q, gait.phases[0].q)
    assert saved.speed * 60 == pytest.approx(12.0, rel=1e-9)
    png, gif = tmp_path / "overview.png", tmp_path / "walk.gif"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert gif.read_bytes()[:6] == b"GIF89a"
