"""One benchmark run of a Python peer: load the mesh arrays, build the solver, propagate from one source.

Run as its own process by run.py (one process per run, so its peak RSS is this run's alone). Imports and
array loading happen before the clocks start; mesh setup and propagation are timed apart where the peer's
API allows it. Distances go to an .npy file with +inf where the peer reports a vertex unreachable (or gives
NaN); timings go to a JSON file.

With --obj instead of the arrays (end_to_end.py), the run starts from the mesh file as a user's script would:
reading it is timed too (read_seconds), with potpourri3d.read_mesh for every peer, so that all of them pay the
same reader (it gives the arrays bench/meshes.py's reader gives, in exactgeo's numbering), and so is writing
the distances (write_seconds).
"""

from __future__ import annotations

import argparse
import importlib
import importlib.metadata
import json
import time

import numpy as np

# Kirsanov's code marks unreachable vertices with GEODESIC_INF = 1e100; anything this large is unreachable.
kKirsanovInfinity = 1e99


def peer_pygeodesic(positions, triangles, source):
    import pygeodesic.geodesic as geodesic

    start = time.perf_counter()
    algorithm = geodesic.PyGeodesicAlgorithmExact(positions, triangles)
    built = time.perf_counter()
    distances, _ = algorithm.geodesicDistances(np.array([source]), None)
    done = time.perf_counter()
    return built - start, done - built, distances


def peer_gdist(positions, triangles, source):
    import gdist

    # compute_gdist builds the mesh and propagates in one call: the build is included in the propagation
    # time (reported build time None).
    start = time.perf_counter()
    distances = gdist.compute_gdist(positions, triangles, source_indices=np.array([source], dtype=np.int32))
    done = time.perf_counter()
    return None, done - start, distances


def peer_libigl(positions, triangles, source):
    import igl

    # exact_geodesic builds, propagates and then traces the path back from every target to measure its
    # length, all in one call: the build and the tracing are included in the propagation time.
    triangles = triangles.astype(np.int64)
    targets = np.arange(len(positions), dtype=np.int64)
    start = time.perf_counter()
    distances = igl.exact_geodesic(positions, triangles, np.array([source], dtype=np.int64), VT=targets)
    done = time.perf_counter()
    return None, done - start, distances


def heat_on_used_vertices(positions, triangles):
    """The used vertices and the new index of each, as geometry-central wants them: it rejects vertices used by
    no face, so solvers run on the used ones, renumbered, and report the others unreachable as the exact
    solvers do."""
    used = np.unique(triangles)
    new_index = np.full(len(positions), -1, dtype=np.int64)
    new_index[used] = np.arange(len(used))
    return used, new_index, positions[used], new_index[triangles]


def peer_heat(positions, triangles, source):
    import potpourri3d

    used, new_index, used_positions, used_triangles = heat_on_used_vertices(positions, triangles)  # before the clocks
    start = time.perf_counter()
    solver = potpourri3d.MeshHeatMethodDistanceSolver(used_positions, used_triangles)
    built = time.perf_counter()
    used_distances = solver.compute_distance(int(new_index[source]))
    done = time.perf_counter()
    distances = np.full(len(positions), np.inf)
    distances[used] = used_distances
    return built - start, done - built, distances


# solver name: (run function, module it imports, PyPI package)
PEERS = {
    "pygeodesic": (peer_pygeodesic, "pygeodesic.geodesic", "pygeodesic"),
    "gdist": (peer_gdist, "gdist", "tvb-gdist"),
    "libigl": (peer_libigl, "igl", "libigl"),
    "heat": (peer_heat, "potpourri3d", "potpourri3d"),
}


def rss_bytes(field: str) -> int:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1]) * 1024
    return 0


def as_peer_arrays(positions, triangles):
    """The dtypes every peer's run function takes (float64 positions, int32 corners), contiguous."""
    return np.ascontiguousarray(positions, dtype=np.float64), np.ascontiguousarray(triangles, dtype=np.int32)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--solver", required=True, choices=sorted(PEERS))
    parser.add_argument("--vertices", help=".npy of float64 (V, 3) positions")
    parser.add_argument("--triangles", help=".npy of (F, 3) zero-based vertex indices")
    parser.add_argument("--obj", help="mesh file to read inside the timed part, instead of the arrays")
    parser.add_argument("--source", required=True, type=int)
    parser.add_argument("--out", help=".npy for the distances")
    parser.add_argument("--stats", required=True, help="JSON for the timings")
    args = parser.parse_args()
    if (args.obj is None) == (args.vertices is None or args.triangles is None):
        parser.error("give either --obj or both --vertices and --triangles")

    run, module, package = PEERS[args.solver]
    importlib.import_module(module)
    read_seconds = None
    if args.obj:
        import potpourri3d  # imported before the clock, as the peer's own module is

        start = time.perf_counter()
        positions, triangles = as_peer_arrays(*potpourri3d.read_mesh(args.obj))
        read_seconds = time.perf_counter() - start
    else:
        positions, triangles = as_peer_arrays(np.load(args.vertices), np.load(args.triangles))
    rss_at_start = rss_bytes("VmRSS")  # interpreter, numpy, the peer's module and the mesh arrays

    build_seconds, propagation_seconds, distances = run(positions, triangles, args.source)

    distances = np.asarray(distances, dtype=np.float64).copy()
    distances[~(np.abs(distances) < kKirsanovInfinity)] = np.inf  # also turns NaN into "unreachable"
    write_seconds = None
    if args.out:
        start = time.perf_counter()
        np.save(args.out, distances)
        write_seconds = time.perf_counter() - start
    stats = {
        "solver": args.solver,
        "package": package,
        "package_version": importlib.metadata.version(package),
        "vertices": len(positions),
        "faces": len(triangles),
        "source": args.source,
        "read_seconds": read_seconds,
        "build_seconds": build_seconds,
        "propagation_seconds": propagation_seconds,
        "write_seconds": write_seconds,
        "rss_at_start_bytes": rss_at_start,
        "peak_rss_self_bytes": rss_bytes("VmHWM"),
        "unreachable": int(np.count_nonzero(~np.isfinite(distances))),
        "max_distance": float(distances[np.isfinite(distances)].max(initial=0.0)),
    }
    with open(args.stats, "w") as file:
        json.dump(stats, file, indent=1)


if __name__ == "__main__":
    main()
