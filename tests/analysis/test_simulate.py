"""Replaying gaits in MuJoCo (``gaitopt.analysis.simulate``, ``gaitopt simulate``).

The gaits are stored solves (``data/``, warm starts stripped): ``gaitopt solve`` (five-link,
12 m/min, ankle torques), ``gaitopt solve --no-ankle`` and ``gaitopt solve --model seven-link
--gait heel-toe --speed 60m/min``, 2026-12-02. Outcomes of simulations are compared with
generous tolerances (contact is soft, torques saturate; the CPU changes the last bits).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.gait.record.file import Gait

os.environ.setdefault("MUJOCO_GL", "egl")  # before MuJoCo loads: headless rendering
mujoco = pytest.importorskip("mujoco")

DATA = Path(__file__).parent / "data"
FIVE = DATA / "five_link_12.gait.json"
FIVE_NO_ANKLE = DATA / "five_link_12_no_ankle.gait.json"
SEVEN = DATA / "seven_link_60.gait.json"


def test_five_link_with_ankle_torques_walks_at_its_speed() -> None:
    """PD 1000, 60 (spectral radius 0.91): four steps, about the gait's speed and steps."""
    from gaitopt.analysis.simulate import simulate_gait

    gait = Gait.load(FIVE)
    lines: list[str] = []
    result = simulate_gait(gait, steps=4, pd=(1000.0, 60.0), progress=lines.append)
    assert not result.fell and result.steps == 4, result.fall_reason
    assert [line.split(":")[0] for line in lines] == [f"step {k}/4" for k in range(1, 5)]
    assert result.speed == pytest.approx(gait.speed, rel=0.15)
    assert np.mean(result.step_lengths) == pytest.approx(gait.step_length, rel=0.15)
    assert result.rms_error < 0.02 and result.max_error < 0.1  # rad
    # the recorded hip moved forward by about the walked distance
    assert result.q[-1, 0] - result.q[0, 0] == pytest.approx(result.distance, abs=0.05)


def test_ankle_torques_matter() -> None:
    """Without its ankle torques (the same gait, the ankles' torques and PD dropped) the
    five-link walk does not keep its speed: the external ankle torques do act."""
    from gaitopt.analysis import simulate as sim

    gait = Gait.load(FIVE)
    data = gait.to_dict()
    model = data["model"]
    keep = [i for i, a in enumerate(model["actuators"]) if "contact" not in a]
    model["actuators"] = [model["actuators"][i] for i in keep]
    for ph in data["phases"]:
        ph["u"] = [[row[i] for i in keep] for row in ph["u"]]
    data["samples"]["u"] = [[row[i] for i in keep] for row in data["samples"]["u"]]
    no_ankles = Gait.from_dict(data)
    with_ankles = sim.simulate_gait(gait, steps=3, pd=(1000.0, 60.0))
    without = sim.simulate_gait(no_ankles, steps=3, pd=(1000.0, 60.0))
    assert not with_ankles.fell
    assert without.fell or abs(without.speed - gait.speed) > 2 * abs(
        with_ankles.speed - gait.speed)


def test_unstabilisable_gait_is_refused_with_its_spectral_radius() -> None:
    """The five-link walk without ankle torques at PD 1000, 60: spectral radius 11.4 (docs),
    refused before any simulation with exit status 3."""
    out = CliRunner().invoke(cli, ["simulate", str(FIVE_NO_ANKLE), "--pd", "1000,60"])
    assert out.exit_code == 3, out.output
    assert "REFUSED" in out.output and "step 1/" not in out.output
    rho = float(re.search(r"spectral radius of the return map is ([0-9.]+)", out.output)[1])
    assert 5.0 < rho < 30.0


def test_a_fall_is_a_result_with_exit_status_1() -> None:
    """Tiny gains cannot hold the five-link walk: it stops within its first steps (a fall;
    ``--force``: simulated although the return map is unstable)."""
    out = CliRunner().invoke(cli, ["simulate", str(FIVE), "--pd", "30,3", "--steps", "4",
                                   "--force"])
    assert out.exit_code == 1, out.output
    assert "FELL after" in out.output and "fall criteria:" in out.output
    assert "contact: contact spheres r = 5 mm" in out.output


def test_mjcf_file_matched_by_name(tmp_path: Path) -> None:
    """``--mjcf FILE`` with gaitopt's own export gives the same walk; without a geom named
    after a contact point it still walks (the touchdown read from the point's height); a file
    whose joint names differ is refused with a line naming the joint."""
    from gaitopt.analysis.mujoco_model import MujocoModelError
    from gaitopt.analysis.simulate import simulate_gait
    from gaitopt.robot.mjcf_export import mjcf_from_model

    gait = Gait.load(FIVE)
    path = tmp_path / "five.xml"
    path.write_text(mjcf_from_model(gait.model))
    own = simulate_gait(gait, steps=2, pd=(1000.0, 60.0))
    from_file = simulate_gait(gait, steps=2, pd=(1000.0, 60.0), mjcf=str(path))
    assert from_file.settings["mjcf"] == str(path)
    np.testing.assert_allclose(from_file.q, own.q, atol=1e-9)
    # a file without a geom named after a contact point: its touchdown read from its height
    ball = tmp_path / "ball.xml"
    ball.write_text(path.read_text().replace('name="tip_2"', 'name="ball_2"'))
    by_height = simulate_gait(gait, steps=2, pd=(1000.0, 60.0), mjcf=str(ball))
    assert not by_height.fell and by_height.steps == 2  # (its tip_2 is solid in mid-swing)
    bad = tmp_path / "renamed.xml"
    bad.write_text(path.read_text().replace('"knee_2"', '"right_knee"'))
    with pytest.raises(MujocoModelError, match="joint 'knee_2'.*right_knee"):
        simulate_gait(gait, steps=1, pd=(1000.0, 60.0), mjcf=str(bad))
    out = CliRunner().invoke(cli, ["simulate", str(FIVE), "--pd", "1000,60", "--mjcf", str(bad)])
    assert out.exit_code == 2 and "knee_2" in out.output


def test_gain_search_takes_the_smallest_radius() -> None:
    """On a 2 x 1 grid without refinement the search returns the pair of smallest spectral
    radius, evaluated by the stability analysis (PD 1000, 60: 0.91, docs/stability.md; 1100,
    60: 1.02), and its tolerance 1e-6 agrees with a tighter integration."""
    from gaitopt.analysis.pd_search import search_gains, spectral_radius

    gait = Gait.load(FIVE)
    found = search_gains(gait, kp_grid=(1100.0, 1000.0), kd_grid=(60.0,), rounds=0)
    assert len(found.evaluations) == 2
    assert found.spectral_radius == min(rho for _, _, rho in found.evaluations)
    assert found.pd == (1000.0, 60.0) and found.stable
    assert found.spectral_radius == pytest.approx(0.91, abs=0.01)
    assert max(rho for _, _, rho in found.evaluations) == pytest.approx(1.02, abs=0.01)
    assert spectral_radius(gait, (1000.0, 60.0), rtol=1e-8) == pytest.approx(
        found.spectral_radius, abs=1e-5)


@pytest.mark.slow
def test_seven_link_walks_ten_steps_with_auto_gains(tmp_path: Path) -> None:
    """The acceptance test: the seven-link optimum at 60 m/min, replayed with the gains
    ``--pd auto`` chooses, walks at least 10 steps without falling (a few minutes: the gain
    search simulates about 25 steps with their variational equations)."""
    video = tmp_path / "walk.gif"
    out = CliRunner().invoke(cli, ["simulate", str(SEVEN), "--pd", "auto", "--steps", "10",
                                   "--video", str(video)])
    print(out.output)  # the search and the steps, for the record (pytest -s)
    assert out.exit_code == 0, out.output
    assert "WALKED 10 steps" in out.output
    assert re.search(r"--pd auto: PD [0-9.e+]+,[0-9.e+]+, spectral radius 0\.[0-9]+ \(stable",
                     out.output)
    if "video:" in out.output:  # MuJoCo's offscreen renderer worked (EGL)
        assert video.stat().st_size > 10_000


def test_stick_figure_video_fallback(tmp_path: Path) -> None:
    """Without an OpenGL context the video is gaitopt's stick figure of the trajectory: one
    frame per state."""
    from PIL import Image

    from gaitopt.viz.mujoco_video import write_stick_gif

    gait = Gait.load(SEVEN)
    q = gait.samples.q[::10]
    path = tmp_path / "stick.gif"
    assert write_stick_gif(gait.model, q, path, fps=25) == len(q)
    with Image.open(path) as im:
        assert im.n_frames == len(q)
