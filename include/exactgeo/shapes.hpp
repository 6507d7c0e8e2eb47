// Meshes the library generates itself: the demo's default mesh, test shapes, and 1-to-4 subdivision.
#pragma once

#include <cstdint>

#include "exactgeo/export.hpp"
#include "exactgeo/mesh.hpp"

namespace exactgeo {

// The most subdivisions of an icosphere: 20 * 4^13 = 1.3 billion faces, the last level whose faces fit 32-bit
// face indices (level 14 would have 5.4 billion). Memory grows fourfold with each level.
inline constexpr int kMaxIcosphereSubdivisions = 13;

// Icosahedron with each face split 1-to-4 `subdivisions` times, vertices projected to the unit sphere.
// 20 * 4^subdivisions faces. Throws exactgeo::Error(invalid_argument) outside 0 to kMaxIcosphereSubdivisions.
EXACTGEO_API MeshSoup make_icosphere(int subdivisions);

// Torus (major radius 1, minor radius 0.35) whose tube radius is modulated by bumps, with
// 2 * major_segments * minor_segments faces: curved, with saddle vertices on the inside. The demo default.
EXACTGEO_API MeshSoup make_bumpy_torus(int major_segments, int minor_segments);

// Flat nx-by-ny grid of squares on [0,width]x[0,height] in the z=0 plane, each square split into two
// triangles along alternating diagonals.
EXACTGEO_API MeshSoup make_grid(int nx, int ny, double width, double height);

// 1-to-4 midpoint subdivision: every triangle becomes four, new vertices at edge midpoints (shared by
// the faces of an edge). The surface is unchanged; original vertices keep their indices.
EXACTGEO_API MeshSoup subdivide_midpoint(const MeshSoup& soup);

}  // namespace exactgeo
