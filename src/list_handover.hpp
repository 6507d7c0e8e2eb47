// A list crossing a face, seen from the mesh: the face's frame, where the windows leaving through each side
// go on, and how they join the list waiting on the other side of that edge. Shared by the sequential driver
// (vtp_engine.cpp) and the parallel bands (parallel_propagation.cpp); inline: asked on every crossing.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

// The triangle entered through halfedge h, in h's frame.
inline FaceFrame face_frame(const SurfaceMesh& mesh, std::uint32_t h) {
  const HalfedgeGeometry& g = mesh.halfedges[h];
  return {g.length, g.apex_x, g.apex_y, mesh.halfedges[prev_halfedge(h)].length,
          mesh.halfedges[next_halfedge(h)].length};
}

// Where windows crossing to `side`, measured from its end `origin`, continue (see SideExit).
inline SideExit exit_through(const SurfaceMesh& mesh, std::uint32_t side, std::uint32_t origin) {
  const std::uint32_t g = mesh.twin[side];
  return {g != kNone, g != kNone && mesh.tail(g) != origin};
}

// How windows crossing an edge join the list on its other side, halfedge `edge` (kNone: a boundary edge,
// where they leave the surface).
enum class Joining : std::uint8_t { prime_merge, inside, wavefront_front, wavefront_back, wavefront_ordered };
struct Handover {
  std::uint32_t edge;
  Joining joining;
  std::uint32_t count;  // windows left after the cut-off
};

// Places the last `added` windows of `list` (an edge's list, extended by the windows arriving there) among
// the ones before them. Rules 2 and 3 prune nothing here: the list is pruned as a whole when it crosses
// (prune_list), once however many runs have joined it.
// - inside (to keep moving), prime_merge (Rule 3's PrimeMerge on a new wavefront edge) and wavefront_back
//   (on an older wavefront edge, from the side of its head): they stay at the end;
// - otherwise they join it by SecondMerge (paper Section 5.1): order-free, windows that came from the side
//   of the edge's tail go first; order-preserving, each is inserted where its start belongs.
inline void join(std::span<Window> list, std::size_t added, Joining joining) {
  const std::size_t old_size = list.size() - added;
  if (joining == Joining::wavefront_front)
    std::rotate(list.begin(), list.begin() + static_cast<std::ptrdiff_t>(old_size), list.end());
  else if (joining == Joining::wavefront_ordered)
    insert_in_order(list, old_size);
}

}  // namespace exactgeo::detail
