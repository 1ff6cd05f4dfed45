"""A gait in a notebook: the summary table, ``plot()`` and ``animate()``."""

from __future__ import annotations

import base64
import copy
import io
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure
from PIL import Image

from gaitopt import Gait
from gaitopt.viz import notebook
from gaitopt.viz.animation import frame_times


def test_the_summary_table_shows_the_gait_and_the_verdict(default_gait: Gait) -> None:
    page = default_gait._repr_html_()
    p = default_gait.parameters
    speed = p["step_length"] / p["step_time"] * 60.0  # m/min, from the step
    for text in (f"{speed:.3f} m/min", f"{p['step_length']:.4f} m", f"{p['step_time']:.4f} s",
                 f"{default_gait.cost_value:.6g}", default_gait.status,
                 f"{default_gait.solver['max_violation']:.3g}", "ankle+impulse",
                 "passed (26 checks)"):
        assert text in page, text
    assert page.startswith("<table>") and page.endswith("</table>")


def test_the_table_of_a_corrupted_gait_names_the_failed_checks(default_gait: Gait) -> None:
    data = copy.deepcopy(default_gait.to_dict())
    data["phases"][0]["u"][3][0] *= 1.05
    bad = Gait.from_dict(data)
    assert "FAILED: eom.residual" in bad._repr_html_()
    assert bad in notebook._VERDICTS  # computed once per gait object


def test_a_failed_solve_is_not_verified(default_gait: Gait) -> None:
    data = copy.deepcopy(default_gait.to_dict())
    data["solver"]["success"] = False
    page = Gait.from_dict(data)._repr_html_()
    assert "not run (the solve failed)" in page and "FAILED" in page  # the solver row


def test_plot_overview_draws_the_samples(default_gait: Gait) -> None:
    fig = default_gait.plot()
    assert isinstance(fig, Figure)
    ax_q, ax_h, ax_u = fig.axes[:3]
    s = default_gait.samples
    model = default_gait.model
    by_label = {line.get_label(): line for line in ax_u.get_lines()}
    for j, act in enumerate(model.actuators):
        np.testing.assert_array_equal(by_label[act.name].get_ydata(), s.u[:, j])
    torso = {line.get_label(): line for line in ax_q.get_lines()}["torso"]
    np.testing.assert_array_equal(torso.get_ydata(), s.q[:, model.coordinate_names.index("torso")])
    hip = {line.get_label(): line for line in ax_h.get_lines()}["hip height [m]"]
    np.testing.assert_array_equal(hip.get_ydata(), s.points["hip"][:, 1])


@pytest.mark.parametrize("kind", ["torques", "hip", "heights", "poses"])
def test_plot_kinds_are_the_report_figures(default_gait: Gait, kind: str) -> None:
    assert isinstance(default_gait.plot(kind), Figure)


def test_plot_rejects_an_unknown_kind(default_gait: Gait) -> None:
    with pytest.raises(ValueError, match="kind: got 'angles'; allowed: overview, torques"):
        default_gait.plot("angles")


def test_animate_inline_is_a_gif_in_real_time(default_gait: Gait) -> None:
    anim = default_gait.animate(steps=1, fps=5)
    assert isinstance(anim, notebook.GifAnimation)
    page = anim._repr_html_()
    prefix = '<img src="data:image/gif;base64,'
    assert page.startswith(prefix)
    data = base64.b64decode(page[len(prefix):].split('"', 1)[0])
    assert data == anim.data
    image = Image.open(io.BytesIO(data))
    assert image.format == "GIF"
    assert image.n_frames == len(frame_times(default_gait.step_time, 5)) == anim.frames


def test_animate_to_a_file_returns_the_path(default_gait: Gait, tmp_path: Path) -> None:
    path = default_gait.animate(tmp_path / "walk.gif", steps=1, fps=5)
    assert path == tmp_path / "walk.gif"
    assert path.read_bytes()[:6] == b"GIF89a"
    with pytest.raises(ValueError, match="unsupported animation file type"):
        default_gait.animate(tmp_path / "walk.avi", steps=1, fps=5)


def test_the_gait_file_module_imports_no_plotting() -> None:
    code = ("import sys, gaitopt.gait.gait_file; "
            "print([m for m in ('matplotlib', 'gaitopt.viz.notebook') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
