"""Meshes the library generates itself, and 1-to-4 subdivision, as (vertices, faces) arrays: float64 (n, 3)
and uint32 (m, 3), ready for exactgeo.Mesh. The same meshes as the command line's @icosphere:K,
@torus:NU:NV and @grid:NX:NY (make_grid(NX, NY, NX, NY)), vertex for vertex."""

from __future__ import annotations

import numpy as np

from . import _core, _inputs


def make_icosphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    """Icosahedron with each face split 1-to-4 `subdivisions` times, vertices on the unit sphere:
    20 * 4**subdivisions faces, from 0 to 13 subdivisions (1.3 billion faces: level 14's would not fit 32-bit
    face indices)."""
    return _core.make_icosphere(_inputs.c_int(subdivisions, "subdivisions"))


def make_bumpy_torus(major_segments: int, minor_segments: int) -> tuple[np.ndarray, np.ndarray]:
    """Torus (radii 1 and 0.35) with a bumpy tube, 2 * major_segments * minor_segments faces: curved, with
    saddle vertices. The command line's demo mesh is make_bumpy_torus(64, 36)."""
    return _core.make_bumpy_torus(
        _inputs.c_int(major_segments, "major_segments"), _inputs.c_int(minor_segments, "minor_segments")
    )


def make_grid(nx: int, ny: int, width: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    """Flat nx-by-ny grid of squares on [0, width] x [0, height] at z = 0, two triangles per square along
    alternating diagonals; vertex (i, j) is number j * (nx + 1) + i."""
    return _core.make_grid(
        _inputs.c_int(nx, "nx"), _inputs.c_int(ny, "ny"), _inputs.real(width, "width"), _inputs.real(height, "height")
    )


def subdivide_midpoint(vertices: object, faces: object) -> tuple[np.ndarray, np.ndarray]:
    """1-to-4 midpoint subdivision: one new vertex per edge at its midpoint; the surface is unchanged and the
    original vertices keep their indices. (n, 2) vertices are taken at z = 0, as exactgeo.Mesh takes them."""
    positions = _inputs.positions_array(vertices)
    return _core.subdivide_midpoint(positions, _inputs.triangles_array(faces, len(positions)))
