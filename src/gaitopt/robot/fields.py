"""Reading plain data (what YAML or JSON parse into) field by field: mappings with known keys,
finite numbers with units, names, pairs, bounds; every problem a one-line :class:`ModelError`
with the field path (``links[1].mass``) used by the model-file schema."""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from typing import Any

from gaitopt.robot.errors import MISSING, ModelError, show_value


def field_path(path: str, key: Any) -> str:
    """The path of ``key`` under ``path``: ``links[1].mass``, or ``links[1]['odd key']``."""
    if isinstance(key, str) and key.isidentifier():
        return f"{path}.{key}" if path else key
    return f"{path}[{show_value(key, 30)}]"


def names_text(names: list[str] | set[str] | tuple[str, ...]) -> str:
    return ", ".join(sorted(names)) or "none defined"


class FieldReader:
    """Reads the fields of plain data from one ``source`` into checked Python values; each
    method takes the field's path (for the error) and raises :class:`ModelError` naming the
    source, the path, the value and what is allowed."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, path: str, value: Any, allowed: str, problem: str | None = None) -> ModelError:
        return ModelError(self.source, path, value, allowed, problem=problem)

    def mapping(self, path: str, value: Any, keys: tuple[str, ...], required: tuple[str, ...],
                what: str) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.fail(path, value, f"a mapping (key: value) describing {what}")
        for key in value:
            if key not in keys:
                raise self.fail(field_path(path, key), value[key],
                                f"the keys {', '.join(keys)}",
                                problem=f"unknown key {show_value(key)}")
        for key in required:
            if key not in value:
                raise self.fail(f"{path}.{key}" if path else key, MISSING,
                                f"'{key}' is required in {what}")
        return value

    def number(self, path: str, value: Any, allowed: str, *, positive: bool = False,
               nonnegative: bool = False) -> float:
        """A finite real number (> 0 if ``positive``, >= 0 if ``nonnegative``); ``allowed``
        describes it with units."""
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            hint = ""
            if isinstance(value, str):
                try:
                    float(value)
                    hint = " (YAML reads numbers like 1e3 as text: write 1.0e+3)"
                except ValueError:
                    pass
            raise self.fail(path, value, allowed + hint)
        try:
            x = float(value)
        except (OverflowError, ValueError, TypeError):
            raise self.fail(path, value, allowed) from None
        if not math.isfinite(x) or (positive and x <= 0.0) or (nonnegative and x < 0.0):
            raise self.fail(path, value, allowed)
        return x

    def name(self, path: str, value: Any) -> str:
        """A name: non-empty printable text without leading or trailing spaces."""
        if (not isinstance(value, str) or not value.strip() or value != value.strip()
                or not value.isprintable()):
            hint = " (quote it in YAML: '1', 'yes')" if isinstance(value, bool | int | float) \
                else ""
            raise self.fail(path, value, "a non-empty printable text without leading or "
                            f"trailing spaces{hint}")
        return value

    def pair(self, path: str, value: Any, allowed: str) -> tuple[float, float]:
        """Two finite numbers ``[a, b]``; ``allowed`` describes them with units."""
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise self.fail(path, value, f"a list of two numbers {allowed}")
        return (self.number(f"{path}[0]", value[0], f"a finite number; {allowed}"),
                self.number(f"{path}[1]", value[1], f"a finite number; {allowed}"))

    def bounds(self, path: str, value: Any, unit: str, *,
               unbounded: bool = False) -> tuple[float, float]:
        """``[lower, upper]`` with lower <= upper; with ``unbounded`` either may be null (no
        bound), read as ``-inf`` (lower) or ``inf`` (upper)."""
        what = f"[lower, upper] in {unit}" + (" (null: no bound)" if unbounded else "")
        if unbounded and isinstance(value, list | tuple) and len(value) == 2:
            lo, hi = (self.number(f"{path}[{i}]", v, f"a finite number or null; {what}")
                      if v is not None else inf
                      for i, (v, inf) in enumerate(zip(value, (-math.inf, math.inf),
                                                       strict=True)))
        else:
            lo, hi = self.pair(path, value, what)
        if lo > hi:
            raise self.fail(path, [lo, hi], f"{what} with lower <= upper",
                            problem=f"lower bound above upper bound {show_value([lo, hi])}")
        return (lo, hi)

    def unique(self, path: str, name: str, seen: set[str], what: str) -> None:
        if name in seen:
            article = "an" if what[0] in "aeiou" else "a"
            raise self.fail(path, name, f"{article} {what} name not used by another {what}",
                            problem=f"duplicate {what} name {show_value(name)}")
        seen.add(name)

    def optional_list(self, path: str, value: Any, what: str) -> list[Any]:
        if value is None:
            return []
        if not isinstance(value, list):
            raise self.fail(path, value, f"a list of {what} (or null for none)")
        return value
