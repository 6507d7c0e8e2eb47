// The windows that reached each face in a run, kept after it (GeodesicOptions::keep_windows) so that the
// exact distance and the shortest path to any surface point can be answered later, as the targets of a run
// are evaluated during it (docs/queries.md gives the argument).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "surface_point.hpp"
#include "vtp_engine.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

// Per surface halfedge, the windows that entered its face through it, in the halfedge's frame: a window list
// of its own (windows.hpp), which the crossings of the run append to and which stays in place for the queries,
// so that the windows are never regrouped or copied as a whole.
class FaceWindows {
 public:
  // Before a run on `threads` threads: forgets the last run's windows, and whether any were kept. for_parts as
  // WindowLists::reset takes it.
  template <class ForParts>
  void start(std::size_t halfedge_count, unsigned threads, ForParts&& for_parts) {
    kept_ = false;
    window_count_ = 0;
    face_sources_.clear();
    lists_.reset(halfedge_count, threads, for_parts);
  }
  bool kept() const { return kept_; }

  // The list entering face(h) through h as it crosses (after Rules 2 and 3, before Rule 1 and the vertex
  // checks, which only prune what leaves the face), added to h's by the thread crossing it, which holds the
  // lock of face(h) if there are several: but the windows that h's corners, at their distances now (final or
  // larger), or the cut-off show useless everywhere in the face.
  void record(const SurfaceMesh& mesh, std::uint32_t h, std::span<const Window> list, double tail_distance,
              double head_distance, double cutoff, const Tolerances& tolerances, unsigned thread);

  // After the run, with every vertex distance final: drops from each halfedge's windows those that the final
  // corner distances, or another window that entered through the same halfedge, show useless everywhere in
  // the face (see the .cpp).
  void finish(const SurfaceMesh& mesh, std::span<const double> vertex_distance, double cutoff,
              std::span<const SourceSite> sources, const Tolerances& tolerances);

  // The kept windows that entered face(h) through h, in h's frame.
  std::span<const Window> entering(std::uint32_t h) const { return lists_.view(h); }
  std::uint64_t window_count() const { return window_count_; }
  // What the kept structure holds in memory: the windows' blocks, a record per halfedge, the sources in faces.
  std::uint64_t bytes(std::size_t halfedge_count) const;

  // The shortest way to `point` (not at a vertex): its length in the engine's frame (+inf if nothing reaches
  // it) and its last straight piece, from the kept windows entering the point's face, the face's corners at
  // their final distances `vertex_distance`, and sources inside the face.
  double reach(const SurfaceMesh& mesh, std::span<const double> vertex_distance, const LocatedPoint& point,
               Arrival& arrival) const;

 private:
  WindowLists lists_;
  bool kept_ = false;
  std::uint64_t window_count_ = 0;
  // Sources inside a face or on an edge (in both faces of the edge), ordered by face.
  struct FaceSource {
    std::uint32_t face;
    std::uint32_t id;    // as in Arrival::from: vertex_count + the source's index
    LocatedPoint point;  // in that face
  };
  std::vector<FaceSource> face_sources_;
};

}  // namespace exactgeo::detail
