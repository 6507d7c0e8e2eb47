// A mesh with one value per vertex (a run's distances, say) as the files that viewers and VTK-based tools
// read: the bytes of a binary legacy VTK file and of a binary PLY file with a colour per vertex. The command's
// `--out d.vtk` and `--out d.ply` and the Python package's save_vtk and save_ply write these bytes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "exactgeo/export.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/mesh.hpp"

namespace exactgeo {

struct VertexValues {
  std::span<const double> values;         // one per vertex, written exactly (inf and NaN included)
  std::string value_name = "distance";    // the VTK array's or PLY property's name: ASCII letters, digits, _
  std::span<const std::uint32_t> labels;  // empty, or one nearest source per vertex: `nearest_source`, -1 for kNoSource
};

// Legacy VTK, binary, for ParaView, VisIt, pyvista and meshio (VTK's PLY reader keeps a PLY's colours, not its
// values): "# vtk DataFile Version 3.0", "written by exactgeo", BINARY, DATASET POLYDATA; POINTS n double (the
// mesh's positions exactly); POLYGONS m 4m (3 and each triangle's corners, int32); POINT_DATA n with SCALARS
// `value_name` double 1 and LOOKUP_TABLE default (the values exactly), then with labels SCALARS nearest_source
// int 1 likewise. Numbers are big-endian, as the format has them; a newline follows each block of them.
// Throws Error(invalid_argument) if values or labels do not have one entry per vertex, or the name is not plain.
EXACTGEO_API std::vector<unsigned char> vtk_file_bytes(const Mesh& mesh, const VertexValues& values);

// Binary little-endian PLY, for MeshLab, Blender or any viewer: "comment written by exactgeo"; element vertex
// with float x, y, z, double `value_name` (the values exactly), with labels int nearest_source, and uchar red,
// green, blue from `colours` (three per vertex); element face with list uchar int vertex_indices (the mesh's
// triangles). Throws as vtk_file_bytes does, and if `colours` does not hold three per vertex.
EXACTGEO_API std::vector<unsigned char> ply_file_bytes(const Mesh& mesh, const VertexValues& values,
                                                       std::span<const std::uint8_t> colours);

// The colour of a vertex without a value (inf or NaN) in the command's pictures and the Python package's.
inline constexpr std::array<std::uint8_t, 3> kNoValueColour = {128, 128, 128};

// The colour ramp of the command's pictures and the Python package's built-in one: five stops of viridis at 0,
// 1/4, 1/2, 3/4 and 1, interpolated linearly in RGB. The colour at t (clamped to [0, 1]) as red, green, blue in
// [0, 255], unrounded; kNoValueColour for NaN.
EXACTGEO_API std::array<double, 3> ramp_colour(double t);

// The command's colours (three per vertex): ramp_colour from 0 to the largest finite value, rounded to the
// nearest; kNoValueColour for inf and NaN.
EXACTGEO_API std::vector<std::uint8_t> ramp_colours(std::span<const double> values);

}  // namespace exactgeo
