"""Checked conversion of what callers pass into the exact arrays and values exactgeo._core takes.

Only what a conversion itself could lose is checked here: a shape other than the one asked for, booleans or
non-numbers where numbers belong, anything but True or False where a flag belongs, a float index that is not
a whole number, an index or a count that does not fit the library's integer types. Each entry point converts
through these helpers, so the same mistake gets the same message wherever it is made. The values themselves
(finite coordinates, indices in range, barycentric coordinates, options) are checked by the library, so
Python, C++ and the command line give the same message for the same mistake. The few messages written here
for values the library cannot even receive (negative indices) follow the library's wording.
"""

from __future__ import annotations

import math
import numbers
import operator
import os
from typing import Any, Callable

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


def positions_array(values: object, what: str = "vertices") -> np.ndarray:
    """(n, 3) float64 coordinates, as real_array makes them; planar (n, 2) ones get z = 0, as libigl and meshio
    take them."""
    array = np.asarray(values)
    if array.ndim == 2 and array.shape[1] == 2:
        array = np.column_stack([array, np.zeros(len(array), dtype=array.dtype)])
    elif array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{what} must have shape (n, 3), or (n, 2) for z = 0, not {array.shape}")
    return real_array(array, what, columns=3)


def index_array(
    values: object, what: str, columns: int | None, element: Callable[[tuple[int, ...]], str], out_of_range: str
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
    if array.dtype == np.int32 and array.flags.c_contiguous:
        return array.view(np.uint32)  # none negative (checked above): the same bits, without a copy
    return np.ascontiguousarray(array, dtype=np.uint32)


def triangles_array(faces: object, vertex_count: int) -> np.ndarray:
    """(m, 3) vertex indices per triangle. Polygons, an (m, k) array with k > 3 or a list of index lists of
    any lengths, are fan-triangulated as the file readers do: (p0, p1, p2), (p0, p2, p3), ... Indices that fit
    32 bits are left for the library to check."""
    out_of_range = f", but the mesh has {vertex_count} vertices"
    polygons = _polygon_list(faces)
    if polygons is None:
        array = np.asarray(faces)
        columns = 3 if array.ndim != 2 or array.shape[1] < 3 else array.shape[1]
        checked = index_array(
            faces, "faces", columns=columns, element=lambda p: f"face {p[0]} names vertex", out_of_range=out_of_range
        )
        if columns == 3:
            return checked
        _check_polygon_range(checked.reshape(-1), np.arange(0, checked.size + 1, columns), vertex_count)
        fan = [np.stack([checked[:, 0], checked[:, i - 1], checked[:, i]], axis=1) for i in range(2, columns)]
        return np.ascontiguousarray(np.stack(fan, axis=1).reshape(-1, 3))
    sizes = np.array([len(polygon) for polygon in polygons], dtype=np.int64)
    if sizes.size and sizes.min() < 3:
        face = int(np.argmax(sizes < 3))
        raise ValueError(f"face {face} has {sizes[face]} vertices; a face needs at least 3")
    starts = np.concatenate([[0], np.cumsum(sizes)])
    flat = np.concatenate([np.asarray(polygon).reshape(-1) for polygon in polygons]) if polygons else np.empty(0)
    indices = index_array(
        flat,
        "faces",
        columns=None,
        element=lambda p: f"face {int(np.searchsorted(starts, p[0], side='right')) - 1} names vertex",
        out_of_range=out_of_range,
    )
    _check_polygon_range(indices, starts, vertex_count)
    triangles = [
        (indices[start], indices[start + i - 1], indices[start + i])
        for start, size in zip(starts[:-1], sizes)
        for i in range(2, size)
    ]
    return np.array(triangles, dtype=np.uint32).reshape(-1, 3)


def _check_polygon_range(indices: np.ndarray, starts: np.ndarray, vertex_count: int) -> None:
    """Named by polygon here: once fanned, the library would count triangles instead."""
    if indices.size and indices.max() >= vertex_count:
        position = int(np.argmax(indices >= vertex_count))
        face = int(np.searchsorted(starts, position, side="right")) - 1
        raise ValueError(f"face {face} names vertex {indices[position]}, but the mesh has {vertex_count} vertices")


def _polygon_list(faces: object) -> list[Any] | None:
    """The faces as a list of index sequences if they are a sequence of sequences of different lengths."""
    if isinstance(faces, np.ndarray) and faces.dtype != object:
        return None
    if not isinstance(faces, (list, tuple, np.ndarray)) or len(faces) == 0:
        return None
    if not all(isinstance(face, (list, tuple, np.ndarray)) for face in faces):
        return None
    lengths = {len(face) for face in faces}
    return list(faces) if len(lengths) > 1 else None


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


def vertex_index(value: object, vertex_count: int, what: str, name: str) -> int:
    """One vertex index, as vertex_array checks it; `name` names it in messages as the library would."""
    if isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.ndim != 0):
        raise TypeError(f"{what} must be one vertex index, not {_brief(value)}")
    return int(vertex_array(value, vertex_count, what, lambda i: name)[0])


def count(value: int, what: str, minimum: int = 0, maximum: int = INDEX_LIMIT - 1) -> int:
    """A whole number of things (samples, threads, a target's number), from `minimum` to `maximum`: the
    default range is the library's unsigned 32-bit one. A bool is refused, not counted as 0 or 1."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{what} must be an integer, not {_brief(value)}")
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"{what} must be an integer, not {_brief(value)}") from None
    if number < minimum:
        raise ValueError(f"{what} must be at least {minimum}, not {number}")
    if number > maximum:
        raise ValueError(f"{what} must be at most {maximum}, not {number}")
    return number


def c_int(value: int, what: str) -> int:
    """An integer the library takes as a C int (a shape's size): only the range of the type is checked here,
    the library checks the value."""
    return count(value, what, minimum=-(2**31), maximum=2**31 - 1)


def flag(value: object, what: str) -> bool:
    """True or False (numpy's too). Anything else is refused rather than taken for its truth value, which
    would read "no" and "False" as true."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise TypeError(f"{what} must be True or False, not {_brief(value)}")


def text(value: object, what: str) -> str:
    """A str, such as a name the library looks up."""
    if isinstance(value, str):
        return value
    raise TypeError(f"{what} must be a string, not {_brief(value)}")


def real(value: object, what: str) -> float:
    """A real number (numpy's too) as a float; a bool is refused, not taken as 0 or 1. Its range is the library's
    or the caller's to check."""
    if not _is_real(value):
        raise TypeError(f"{what} must be a number, not {_brief(value)}")
    return float(value)  # type: ignore[arg-type]


def optional_real(value: object, what: str) -> float | None:
    """None, or a real number as real() takes it."""
    if value is not None and not _is_real(value):
        raise TypeError(f"{what} must be a number or None, not {_brief(value)}")
    return None if value is None else float(value)  # type: ignore[arg-type]


def _is_real(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def reals(values: object, what: str, size: int | None = None) -> np.ndarray:
    """One number or a 1-D sequence of them (exactly `size` if given) as a float64 array."""
    try:
        array = np.asarray(values)
    except ValueError:  # a ragged nesting
        array = np.empty(0, dtype=object)
    if array.dtype.kind not in "fiu" or array.ndim > 1 or (size is not None and array.shape != (size,)):
        wanted = f"{size} numbers" if size is not None else "a number or a 1-D sequence of numbers"
        raise TypeError(f"{what} must be {wanted}, not {_brief(values)}")
    return np.atleast_1d(array.astype(np.float64))


def cutoff(max_distance: float | None) -> float:
    """None means no cut-off; the library checks that a given one is not negative or NaN."""
    checked = optional_real(max_distance, "max_distance")
    return math.inf if checked is None else checked


def path(value: object, what: str = "path") -> bytes:
    """A file name as the bytes the system takes: from a str (undecodable bytes kept, as os.fsencode keeps
    them), bytes, or an os.PathLike of either."""
    try:
        return os.fsencode(value)  # type: ignore[arg-type]
    except TypeError:
        raise TypeError(f"{what} must be a str, bytes or os.PathLike, not {type(value).__name__}") from None


def _check_shape(array: np.ndarray, what: str, columns: int | None) -> None:
    """(n, columns), or 1-D (indices) without columns."""
    if columns is None and array.ndim != 1:
        raise ValueError(
            f"{what} must be a single index or a 1-D array of indices, not an array of shape {array.shape}"
        )
    if columns is not None and (array.ndim != 2 or array.shape[1] != columns):
        raise ValueError(f"{what} must have shape (n, {columns}), not {array.shape}")


def _first(mask: np.ndarray) -> tuple[int, ...]:
    return tuple(int(i) for i in np.argwhere(mask)[0])


def _plain(value: np.generic) -> object:
    """1.5 and -1 rather than np.float64(1.5) and np.int64(-1) in messages."""
    number = value.item()
    return int(number) if isinstance(number, float) and number.is_integer() else number


def _brief(value: object) -> str:
    """A value as a message quotes it: its repr, cut to a line."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}..."


def _dtype_text(array: np.ndarray) -> str:
    return "objects" if array.dtype.kind == "O" else f"dtype {array.dtype}"
