"""The views of a gait (its notebook summary, figures and animation), as the gait record sees
them: a protocol and the one place its implementation is found.

:class:`~gaitopt.gait.gait_file.Gait` has ``_repr_html_``, ``plot`` and ``animate``, but
``gait/`` sits below ``viz/`` (docs/architecture.md) and may not import it, not even inside a
function. So the record asks this module for a :class:`GaitViews`, and the front door
(``gaitopt/__init__.py``, which alone may import every package) installs the loader of the
implementation, :mod:`gaitopt.viz.notebook`, when the package is imported. Nothing loads
Matplotlib before a view is first asked for.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any, Protocol


class GaitViews(Protocol):
    """What a gait's notebook methods call (:mod:`gaitopt.viz.notebook` is one)."""

    def summary_html(self, gait: Any, *, verify: bool = True) -> str:
        """The HTML table Jupyter shows for a gait."""

    def gait_figure(self, gait: Any, kind: str = "overview") -> Any:
        """A Matplotlib figure of the gait of the given kind."""

    def animate(self, gait: Any, path: str | os.PathLike[str] | None = None, *,
                steps: int = 4, fps: int = 30) -> Any:
        """An animation written to ``path`` (returns the path) or held in memory."""


_loader: Callable[[], GaitViews] | None = None


def install_gait_views(loader: Callable[[], GaitViews]) -> None:
    """Set the function that returns the views (called on each use; it may import them)."""
    global _loader
    _loader = loader


def gait_views() -> GaitViews:
    """The installed views.

    Raises:
        RuntimeError: none is installed (the front door installs them on ``import gaitopt``,
            which every import of a gaitopt module runs first).
    """
    if _loader is None:
        raise RuntimeError("no gait views installed: gaitopt/__init__.py installs them")
    return _loader()
