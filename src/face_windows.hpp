// The windows that reached each face in a run, kept after it (GeodesicOptions::keep_windows) so that the
// exact distance and the shortest path to any surface point can be answered later, as the targets of a run
// are evaluated during it (docs/queries.md gives the argument).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "surface_point.hpp"
#include "vtp_engine.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

class FaceWindows {
 public:
  // Before a run on `threads` threads: forgets the last run's windows, and whether any were kept.
  void start(unsigned threads);
  bool kept() const { return kept_; }

  // The list entering face(h) through h as it crosses (after Rules 2 and 3, before Rule 1 and the vertex
  // checks, which only prune what leaves the face), logged by the thread crossing it: but the windows that
  // h's corners, at their distances now (final or larger), or the cut-off show useless everywhere in the face.
  void record(const SurfaceMesh& mesh, std::uint32_t h, std::span<const Window> list, double tail_distance,
              double head_distance, double cutoff, const Tolerances& tolerances, unsigned thread);

  // After the run, with every vertex distance final: groups the logged windows by the halfedge they entered
  // through, and drops those that the final corner distances, or another window entering through the same
  // halfedge, show useless everywhere in the face (see the .cpp).
  void finish(const SurfaceMesh& mesh, std::span<const double> vertex_distance, double cutoff,
              std::span<const SourceSite> sources, const Tolerances& tolerances);

  // The kept windows that entered face(h) through h, in h's frame.
  std::span<const Window> entering(std::uint32_t h) const {
    return {windows_.data() + offsets_[h], windows_.data() + offsets_[h + 1]};
  }
  std::uint64_t window_count() const { return windows_.size(); }
  // What the kept structure holds in memory: the windows, the per-halfedge offsets and the sources in faces.
  std::uint64_t bytes() const;

  // The shortest way to `point` (not at a vertex): its length in the engine's frame (+inf if nothing reaches
  // it) and its last straight piece, from the kept windows entering the point's face, the face's corners at
  // their final distances `vertex_distance`, and sources inside the face.
  double reach(const SurfaceMesh& mesh, std::span<const double> vertex_distance, const LocatedPoint& point,
               Arrival& arrival) const;

 private:
  struct Crossing {
    std::uint32_t halfedge, count;
  };
  // Logged windows in chunks that never move: a log that grows by copying would hold its old and new copies
  // at once, twice the memory the windows need, and the log is most of a keeping run's memory. A chunk is
  // 48 MB of address space, of which only what is written becomes memory: blocks that large the allocator
  // maps on their own (glibc: above 32 MB) and gives back to the system when freed, so that finish() can
  // free each chunk as it moves the windows out (a smaller block freed inside the heap stays the process's).
  static constexpr std::size_t kChunkWindows = std::size_t{1} << 20;
  struct alignas(64) Log {  // a cache line of its own: each thread appends to its own
    std::vector<std::unique_ptr<Window[]>> chunks;
    std::size_t last_chunk_size = kChunkWindows;  // windows in the newest chunk (full: none yet)
    std::vector<Crossing> crossings;
    void push(const Window& w) {
      if (last_chunk_size == kChunkWindows) {
        chunks.push_back(std::make_unique_for_overwrite<Window[]>(kChunkWindows));
        last_chunk_size = 0;
      }
      chunks.back()[last_chunk_size++] = w;
    }
  };
  std::vector<Log> logs_;
  bool kept_ = false;
  std::vector<std::uint32_t> offsets_;  // per surface halfedge, and one past the last
  std::vector<Window> windows_;
  // Sources inside a face or on an edge (in both faces of the edge), ordered by face.
  struct FaceSource {
    std::uint32_t face;
    std::uint32_t id;  // as in Arrival::from: vertex_count + the source's index
    LocatedPoint point;  // in that face
  };
  std::vector<FaceSource> face_sources_;
};

}  // namespace exactgeo::detail
