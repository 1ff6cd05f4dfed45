"""The error of an invalid model description: :class:`ModelError`, one line naming the source,
the field path, the bad value and what is allowed (raised by the schema, the YAML loader and
the URDF import and export)."""

from __future__ import annotations

from typing import Any


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


#: Stands for the value of a required field that is absent.
MISSING: Any = _Missing()


def show_value(value: Any, limit: int = 60) -> str:
    """A one-line, length-limited ``repr`` of a value for error messages."""
    try:
        text = repr(value)
    except Exception:  # a repr that fails must not hide the real error
        text = f"<{type(value).__name__}>"
    text = " ".join(text.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


class ModelError(ValueError):
    """A model file or description is invalid.

    The message is one line: ``SOURCE: PATH: got VALUE; allowed: ALLOWED`` (``missing`` instead
    of ``got VALUE`` for an absent required field, or another ``problem`` text).

    Attributes:
        source: the file (or ``<builtin NAME>``, ``<dict>``, ``<string>``) the model came from.
        path: the field path, e.g. ``links[2].mass``; ``""`` for the whole file.
        value: the offending value (:data:`MISSING` for an absent field).
        allowed: what would have been accepted.
    """

    def __init__(self, source: str, path: str, value: Any, allowed: str, *,
                 problem: str | None = None) -> None:
        self.source, self.path, self.value, self.allowed = source, path, value, allowed
        if problem is None:
            problem = "missing" if value is MISSING else f"got {show_value(value)}"
        where = f"{path}: " if path else ""
        super().__init__(f"{source}: {where}{problem}; allowed: {allowed}")
