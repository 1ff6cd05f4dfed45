"""Checked fields of gait data: the one error type of gait files and the checks of single
values (arrays of a shape, finite numbers, mappings with required keys, plain JSON data).

:mod:`gaitopt.gait.record.parts` and :mod:`gaitopt.gait.record.file` build their records with
these; every failure is a :class:`GaitFileError` naming the field path, which the file reader
prefixes with the file and the enclosing field.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


class GaitFileError(ValueError):
    """A gait file or gait data is invalid: names the source, the field path and the problem."""

    def __init__(self, source: str, path: str, message: str) -> None:
        self.source, self.path, self.message = source, path, message
        where = f"{path}: " if path else ""
        super().__init__(f"{source}: {where}{message}")


def bad_field(path: str, message: str) -> GaitFileError:
    """The error of field ``path`` of gait data given to a constructor (source ``<Gait>``)."""
    return GaitFileError("<Gait>", path, message)


def array_of(path: str, value: Any, shape: tuple[int | None, ...]) -> Array:
    """A read-only float array of the given shape (None = any length), finite."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise bad_field(path, f"expected numbers in an array of shape {_shape_text(shape)}"
                        ) from None
    if arr.ndim != len(shape) or any(n is not None and n != m for n, m in zip(shape, arr.shape,
                                                                             strict=True)):
        raise bad_field(path, f"expected shape {_shape_text(shape)}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise bad_field(path, "contains NaN or infinite values")
    arr.setflags(write=False)
    return arr


def _shape_text(shape: tuple[int | None, ...]) -> str:
    return "(" + ", ".join("N" if n is None else str(n) for n in shape) + ")"


def number_of(path: str, value: Any, *, minimum: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.number):
        raise bad_field(path, f"expected a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise bad_field(path, f"expected a finite number, got {value!r}")
    if minimum is not None and x < minimum:
        raise bad_field(path, f"expected a number >= {minimum:g}, got {x:g}")
    return x


def mapping_of(path: str, value: Any, required: Sequence[str] = ()) -> dict[str, Any]:
    if not isinstance(value, Mapping):
        raise bad_field(path, f"expected an object (mapping), got {type(value).__name__}")
    for key in required:
        if key not in value:
            raise bad_field(path, f"missing required key {key!r}")
    return dict(value)


def plain_json(path: str, value: dict[str, Any]) -> dict[str, Any]:
    """``value`` if it is plain JSON data (no NaN, no numpy or other objects)."""
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise bad_field(path, f"must be plain JSON data: strings, finite numbers, booleans, "
                        f"null, lists and objects ({exc})") from None
    return value


def frozen_copy(value: Mapping[str, Any]) -> Mapping[str, Any]:
    return MappingProxyType(copy.deepcopy(dict(value)))


def check_increasing(path: str, t: Array) -> None:
    if t.size and np.any(np.diff(t) <= 0.0):
        raise bad_field(path, "times must be strictly increasing")
