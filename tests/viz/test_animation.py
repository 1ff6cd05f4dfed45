"""Animations: real-time frame timing, frame counts, file types."""

from __future__ import annotations

from pathlib import Path

import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

from gaitopt.gait.record.file import Gait
from gaitopt.viz.animation import animate_gait, contact_forces_at, frame_times, gif_delays_ms
from tests.viz.synthetic import synthetic_gait


@pytest.fixture(scope="module")
def gait() -> Gait:
    return synthetic_gait(speed=0.5, step_length=0.3, n_samples=41)  # step time 0.6 s


def test_frame_times_and_gif_delays_track_real_time() -> None:
    np.testing.assert_allclose(frame_times(1.2, 10), np.arange(13) / 10)
    delays = gif_delays_ms(100, 30)
    assert all(d % 10 == 0 for d in delays) and set(delays) == {30, 40}
    assert np.max(np.abs(np.cumsum(delays) - np.arange(1, 101) * 1000 / 30)) <= 5.0
    assert sum(delays) == 3330  # 100 frames at 30 fps = 3.333 s, to 10 ms


def test_gif_has_one_frame_per_tick_and_real_time_duration(gait: Gait, tmp_path: Path) -> None:
    info = animate_gait(gait, tmp_path / "walk.gif", steps=2, fps=15, dpi=40)
    assert info.frames == 19  # t = 0, 1/15, ..., 1.2 s (2 steps of 0.6 s)
    with Image.open(info.path) as image:
        durations = []
        for k in range(image.n_frames):
            image.seek(k)
            durations.append(image.info["duration"])
        assert image.n_frames == 19
    assert sum(durations) == pytest.approx(19 / 15 * 1000, abs=10)
    assert not list(tmp_path.glob(".*"))  # no temporary left


def test_mp4_frame_count_and_duration(gait: Gait, tmp_path: Path) -> None:
    info = animate_gait(gait, tmp_path / "walk.mp4", steps=1, fps=10, dpi=40)
    frames, seconds = imageio_ffmpeg.count_frames_and_secs(str(info.path))
    assert frames == info.frames == 7
    assert seconds == pytest.approx(0.7, abs=0.05)


def test_bad_requests_get_clear_errors(gait: Gait, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"unsupported animation file type '\.avi'.*\.gif"):
        animate_gait(gait, tmp_path / "walk.avi")
    with pytest.raises(ValueError, match="steps"):
        animate_gait(gait, tmp_path / "walk.gif", steps=0)
    with pytest.raises(ValueError, match="fps"):
        animate_gait(gait, tmp_path / "walk.gif", fps=0)
    assert not list(tmp_path.iterdir())


def test_contact_forces_follow_the_phases(gait: Gait) -> None:
    t1 = gait.parameters["single_support_time"]
    assert set(contact_forces_at(gait, 0.5 * t1)) == {"tip_1"}
    double = gait.phases[1]
    mid = 0.5 * (double.t[1] + double.t[2])
    both = contact_forces_at(gait, mid)
    assert set(both) == {"tip_1", "tip_2"}
    for tip in ("tip_1", "tip_2"):  # linear between knots
        f = double.contact_forces[tip]
        np.testing.assert_allclose(both[tip], 0.5 * (f[1] + f[2]))
        np.testing.assert_allclose(contact_forces_at(gait, double.t[3])[tip], f[3])
    assert contact_forces_at(gait, 2 * gait.step_time) == {}
