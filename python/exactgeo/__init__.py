"""Exact geodesic distances on triangle meshes, from numpy arrays.

    import exactgeo
    mesh = exactgeo.Mesh(vertices, faces)      # (n, 3) coordinates, (m, 3) vertex indices, any dtype
    d = exactgeo.distance(mesh, 0)             # float64 per vertex, inf where unreachable
    p = exactgeo.path(mesh, 0, 42)             # p.points: (k, 3) polyline on the surface

The engine is the C++ library's VTP implementation (Qin et al., SIGGRAPH 2016), exact up to double
precision. Bad input raises ValueError with the library's message naming the element at fault; files that
cannot be read raise OSError. See docs/python.md in the repository for a guide.
"""

from ._core import GeodesicStats, MeshReport, version as __version__
from ._geodesic import ALGORITHMS, AlgorithmOptions, GeodesicPath, GeodesicResult, GeodesicSolver, distance, path
from ._isolines import isolines
from ._many_sources import Sampling, distance_matrix, farthest_point_sampling
from ._mesh import Mesh
from ._pairs import pair_distances
from ._pictures import plot, save_ply, save_vtk
from ._shapes import make_bumpy_torus, make_grid, make_icosphere, subdivide_midpoint
from ._surface_point import SurfacePoint, SurfacePoints, edge_point, locate, point_position, vertex_point

__all__ = [
    "ALGORITHMS",
    "AlgorithmOptions",
    "GeodesicPath",
    "GeodesicResult",
    "GeodesicSolver",
    "GeodesicStats",
    "Mesh",
    "MeshReport",
    "Sampling",
    "SurfacePoint",
    "SurfacePoints",
    "__version__",
    "distance",
    "distance_matrix",
    "edge_point",
    "farthest_point_sampling",
    "isolines",
    "locate",
    "make_bumpy_torus",
    "make_grid",
    "make_icosphere",
    "pair_distances",
    "path",
    "plot",
    "point_position",
    "save_ply",
    "save_vtk",
    "subdivide_midpoint",
    "vertex_point",
]
