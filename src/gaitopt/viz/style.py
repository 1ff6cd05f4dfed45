"""Figure creation, saving and the line styles shared by all figures.

Figures are :class:`matplotlib.figure.Figure` objects on an Agg canvas, built without pyplot
(no global state, no display needed). Line styles follow the paper's figures: for the four
variants, with ankle torques solid, without dashed, ankle + impulse dash-dot, impulse only
dotted.
"""

from __future__ import annotations

import base64
import io
import os
from pathlib import Path
from typing import Any

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from gaitopt.fileio import write_bytes_atomic

#: Paper Fig. 3/4 line styles by variant.
VARIANT_STYLES: dict[str, dict[str, Any]] = {
    "ankle": {"color": "C0", "linestyle": "-"},
    "plain": {"color": "C1", "linestyle": "--"},
    "ankle+impulse": {"color": "C2", "linestyle": "-."},
    "impulse": {"color": "C3", "linestyle": ":"},
}
VARIANT_LABELS: dict[str, str] = {
    "ankle": "ankle torques, no impulse",
    "plain": "no ankle torques, no impulse",
    "ankle+impulse": "ankle torques + liftoff impulse",
    "impulse": "liftoff impulse, no ankle torques",
}
#: Styles for overlaid gaits (paper Figs. 5-8: slow with/without ankles solid/dashed, fast
#: with/without ankles dash-dot/dotted), then cycling colours.
GAIT_STYLES: tuple[dict[str, Any], ...] = (
    {"color": "C0", "linestyle": "-"},
    {"color": "C1", "linestyle": "--"},
    {"color": "C2", "linestyle": "-."},
    {"color": "C3", "linestyle": ":"},
    {"color": "C4", "linestyle": "-"},
    {"color": "C5", "linestyle": "--"},
    {"color": "C6", "linestyle": "-."},
    {"color": "C7", "linestyle": ":"},
)
LEG_COLORS: tuple[str, str] = ("#1f4e9c", "#e07b00")  # leg 1, leg 2
EVENT_LINE: dict[str, Any] = {"color": "0.6", "linewidth": 0.8, "linestyle": "-", "zorder": 0}
BOUND_LINE: dict[str, Any] = {"color": "0.35", "linewidth": 1.0, "linestyle": (0, (6, 3)),
                              "zorder": 0}


def gait_style(i: int) -> dict[str, Any]:
    return dict(GAIT_STYLES[i % len(GAIT_STYLES)])


def new_figure(width: float, height: float) -> Figure:
    """A figure of ``width`` x ``height`` inches on an Agg canvas."""
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def png_bytes(fig: Figure, *, dpi: int = 110) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def svg_text(fig: Figure) -> str:
    buffer = io.StringIO()
    fig.savefig(buffer, format="svg", metadata={"Date": None})
    return buffer.getvalue()


def png_data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def save_figure(fig: Figure, out_dir: str | os.PathLike[str], stem: str, *,
                dpi: int = 110, svg: bool = True) -> tuple[list[Path], bytes]:
    """Write ``<stem>.png`` (and ``<stem>.svg``) atomically; returns the paths and the PNG."""
    folder = Path(out_dir)
    png = png_bytes(fig, dpi=dpi)
    paths = [folder / f"{stem}.png"]
    write_bytes_atomic(paths[0], png)
    if svg:
        fig.set_layout_engine("none")  # keep the layout the PNG was drawn with (faster)
        paths.append(folder / f"{stem}.svg")
        write_bytes_atomic(paths[1], svg_text(fig).encode("utf-8"))
    return paths, png
