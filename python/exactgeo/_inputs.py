"""Checked conversion of what callers pass into the exact arrays exactgeo._core takes.

Only what a conversion itself could lose is checked here: a shape other than the one asked for, booleans or
non-numbers where numbers belong, a float index that is not a whole number, an index that does not fit the
library's 32-bit indices. The values themselves (finite coordinates, indices in range, barycentric
coordinates, options) are checked by the library, so Python, C++ and the command line give the same message
for the same mistake. The few messages written here for values the library cannot even receive (negative
indices) follow the library's wording.
"""

from __future__ import annotations

import math
import operator
from typing import Callable

import numpy as np

# The library's indices are 32-bit unsigned.
INDEX_LIMIT = 2**32


def real_array(values: object, what: str, columns: int) -> np.ndarray:
    """A C-ordered float64 copy (or the array itself if it already is one) of shape (n, columns)."""
    array = np.asarray(values)
    if array.dtype.kind not in "fiu":
        raise ValueError(f"{what} must be real numbers, not {_dtype_text(array)}")
    _check_shape(array, what, columns)
    return np.ascontiguousarray(array, dtype=np.float64)


def index_array(
    values: object, what: str, columns: int | None, element: Callable[[tuple], str], out_of_range: str
) -> np.ndarray:
    """A C-ordered uint32 array of indices from any integer dtype, or floats holding whole numbers: 1-D, or
    of shape (n, columns).

    A bad element is named as `element(position)` followed by its value: "face 3 names vertex" -1, "source
    vertex" -1; `out_of_range` ends the message for an index that does not fit, e.g. ", but the mesh has
    10 vertices". `what` names the whole argument.
    """
    array = np.asarray(values)
    if array.size == 0:  # [] comes in as float64: nothing to convert
        array = array.astype(np.uint32)
    kind = array.dtype.kind
    if kind == "b":
        raise ValueError(f"{what} must be integer indices, not booleans (np.flatnonzero turns a mask into indices)")
    if kind not in "fiu":
        raise ValueError(f"{what} must be integer indices, not {_dtype_text(array)}")
    _check_shape(array, what, columns)
    if kind == "f":
        whole = np.isfinite(array) & (np.floor(array) == array)
        if not whole.all():
            position = _first(~whole)
            raise ValueError(f"{what} must be whole numbers: {element(position)} {_plain(array[position])}")
    # Only the bounds the dtype allows are scanned for (the common int32 needs one pass, uint32 none). Floats
    # are compared as float64: exact for every index that fits 32 bits.
    may_be_negative = kind != "u"
    may_be_too_large = kind == "f" or array.dtype.itemsize > 4
    if array.size and ((may_be_negative and array.min() < 0) or (may_be_too_large and array.max() >= INDEX_LIMIT)):
        position = _first((array < 0) | (array >= INDEX_LIMIT))
        raise ValueError(f"{element(position)} {_plain(array[position])}{out_of_range}")
    return np.ascontiguousarray(array, dtype=np.uint32)


def triangles_array(faces: object, vertex_count: int) -> np.ndarray:
    """(m, 3) vertex indices per face. Indices that fit 32 bits are left for the library to check."""
    return index_array(
        faces,
        "faces",
        columns=3,
        element=lambda position: f"face {position[0]} names vertex",
        out_of_range=f", but the mesh has {vertex_count} vertices",
    )


def vertex_array(vertices: object, vertex_count: int, what: str, name: Callable[[int], str]) -> np.ndarray:
    """A single vertex index or a 1-D array of them, as a 1-D uint32 array.

    `name(i)` names element i as the library does: "source vertex", "target 3: vertex", "vertex".
    """
    # One plain index is the common case; checking it here keeps a query on a small mesh cheap.
    if isinstance(vertices, (int, np.integer)) and not isinstance(vertices, bool) and 0 <= vertices < INDEX_LIMIT:
        return np.array([vertices], dtype=np.uint32)
    array = np.asarray(vertices)
    return index_array(
        array.reshape(1) if array.ndim == 0 else array,
        what,
        columns=None,
        element=lambda position: name(position[0]),
        out_of_range=f" is out of range (mesh has {vertex_count} vertices)",
    )


def count(value: int, what: str, minimum: int = 0, maximum: int = INDEX_LIMIT - 1) -> int:
    """A whole number of things (samples, threads, a target's number), from `minimum` to `maximum`."""
    try:
        number = operator.index(value)
    except TypeError:
        raise ValueError(f"{what} must be an integer, not {value!r}") from None
    if number < minimum:
        raise ValueError(f"{what} must be at least {minimum}, not {number}")
    if number > maximum:
        raise ValueError(f"{what} must be at most {maximum}, not {number}")
    return number


def cutoff(max_distance: float | None) -> float:
    """None means no cut-off; the library checks that a given one is not negative or NaN."""
    return math.inf if max_distance is None else float(max_distance)


def _check_shape(array: np.ndarray, what: str, columns: int | None) -> None:
    """(n, columns), or 1-D (indices) without columns."""
    if columns is None and array.ndim != 1:
        raise ValueError(
            f"{what} must be a single index or a 1-D array of indices, not an array of shape {array.shape}"
        )
    if columns is not None and (array.ndim != 2 or array.shape[1] != columns):
        raise ValueError(f"{what} must have shape (n, {columns}), not {array.shape}")


def _first(mask: np.ndarray) -> tuple:
    return tuple(int(i) for i in np.argwhere(mask)[0])


def _plain(value: np.generic) -> object:
    """1.5 and -1 rather than np.float64(1.5) and np.int64(-1) in messages."""
    number = value.item()
    return int(number) if isinstance(number, float) and number.is_integer() else number


def _dtype_text(array: np.ndarray) -> str:
    return "objects" if array.dtype.kind == "O" else f"dtype {array.dtype}"
