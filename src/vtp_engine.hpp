// The VTP engine (paper Section 5.2, Algorithm 1): a priority queue of wavefront vertices; popping one adds
// its unvisited faces to the traversed area and propagates the window lists entering them, and whatever
// those lists reach inside the traversed area, until every list is pruned, has died on the boundary or
// waits on an edge of the wavefront.
//
// The paper's other variants share everything but the wavefront order and the secondary merge (Section
// 5.1): the face-sorted ones (FTP, OPFTP) keep a priority queue of triangles instead, adding one per
// iteration, and the order-preserving ones (OPVTP, OPFTP) insert windows arriving at an older wavefront edge
// in order of their start instead of prepending or appending them as a block.
//
// Generalisations over the paper, each costing nothing when unused: sources at points inside faces and on
// edges, a distance cut-off (windows that cannot reach below it are dropped), target points whose distances
// are evaluated as window lists cross their faces (the cut-off then shrinks to the farthest target),
// per-vertex arrivals from which paths are traced back, on request the lists that crossed each face, kept so
// that any point can be evaluated after the run as targets are during it (face_windows.hpp), and
// goal-directed runs towards one target (docs/pairs.md).
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "arrival.hpp"
#include "engine_state.hpp"
#include "exactgeo/geodesic.hpp"
#include "goal.hpp"
#include "list_handover.hpp"
#include "parallel_propagation.hpp"
#include "surface_point.hpp"
#include "wavefront_queue.hpp"

namespace exactgeo::detail {

// The face-sorted variants (FTP, OPFTP): a queue of triangles, not of vertices.
inline bool sorts_faces(Algorithm algorithm) { return algorithm == Algorithm::ftp || algorithm == Algorithm::opftp; }

class FaceWindows;  // face_windows.hpp

// A source of a run: a surface vertex (point.vertex set) or a point inside a face or on an edge, and the
// index of the user's source it stands for.
struct SourceSite {
  LocatedPoint point;
  std::uint32_t label;
};

// Source `label` at an input vertex: a source at each of its surface copies.
inline void add_vertex_sources(std::vector<SourceSite>& sites, std::span<const std::uint32_t> copies,
                               std::uint32_t label) {
  for (const std::uint32_t copy : copies) sites.push_back({LocatedPoint{.vertex = copy}, label});
}

// Throws Error(invalid_argument) for options no run can use: an algorithm value outside the enum, a
// max_distance that is negative or NaN. The one check of them, made before any work.
void check_options(const GeodesicOptions& options);

class VtpEngine {
 public:
  explicit VtpEngine(const SurfaceMesh& mesh);
  ~VtpEngine();

  void run(std::span<const SourceSite> sources, std::span<const LocatedPoint> targets,
           const GeodesicOptions& options);
  void set_progress(std::function<void(double)> callback) { progress_ = std::move(callback); }
  // Goal-directed runs (docs/pairs.md): from the next run on, a run with exactly one target on one thread orders
  // its wavefront by distance plus the straight-line distance to the target (A*), and drops a window or a
  // pseudo-source's emission once no path through it can reach the target within the cut-off. Only the
  // target's distance is then exact: vertex distances are upper bounds, exact along its shortest path.
  void set_goal_directed(bool on) { goal_directed_ = on; }

  // Distances above the cut-off are not final: reported as +inf. Lengths are in the mesh's engine frame
  // (SurfaceMesh::scale_exponent).
  double cutoff() const { return state_.cutoff; }
  // Whether the run answers distance d (engine frame): reached, and within the cut-off. Not `d <= cutoff`
  // alone: +inf passes that when there is no cut-off.
  bool answers(double d) const { return d < HUGE_VAL && d <= answered_up_to_; }
  std::span<const double> distances() const { return state_.distance; }  // per surface vertex
  std::span<const Arrival> arrivals() const { return state_.arrival; }   // per surface vertex
  // Every surface vertex the last run gave a finite distance (some of them beyond the cut-off), in the order
  // it reached them, so that a run that stopped early can be read in the time it took; none if the run
  // cannot list them (on several threads, face-sorted, or stopped), when distances() is to be read whole.
  std::optional<std::span<const std::uint32_t>> reached_vertices() const {
    if (!reached_complete_) return std::nullopt;
    return reached_;
  }
  const std::vector<double>& target_distances() const { return state_.targets.distances(); }
  const std::vector<Arrival>& target_arrivals() const { return state_.targets.arrivals(); }
  const std::vector<SourceSite>& sources() const { return sources_; }
  // Per surface vertex, the label of the source there, kNone elsewhere (nearest_source.hpp reads them).
  std::span<const std::uint32_t> source_labels() const { return state_.source_label; }
  const SurfaceMesh& mesh() const { return mesh_; }
  const std::vector<LocatedPoint>& targets() const { return state_.targets.points(); }
  const GeodesicStats& stats() const { return stats_; }
  // The windows the last run kept for queries at any point (GeodesicOptions::keep_windows); null if it kept
  // none, or did not finish.
  const FaceWindows* kept_windows() const;

  // Calls work(begin, end) over [0, count) cut into one part per thread of the last run, on its threads.
  template <class Work>
  void for_parts(std::size_t count, Work&& work) {
    if (threads_ == 1) return work(std::size_t{0}, count);
    parallel_->for_parts(count, work);
  }

 private:
  friend class ParallelPropagation;  // the parallel twins of the steps below

  void reset_state();
  void reset_reached();
  bool state_is_reset() const;
  void run_vertex_sorted();
  void enclose_vertex(std::uint32_t v);
  void move_inside(std::uint32_t v);
  void enter_faces_of(std::uint32_t v);
  void run_face_sorted();
  // Vertex (or face) pops between two progress reports and checks for a stop request: a few milliseconds.
  static constexpr std::uint64_t kProgressInterval = 4096;
  void checkpoint(std::uint64_t pops, double fraction);
  void enter_face(std::uint32_t f);
  void join_face(std::uint32_t f);
  void start_point_source(std::uint32_t site);
  void relax(std::uint32_t v, double d, const Arrival& arrival);
  void push_vertex(std::uint32_t v, double d);
  void queue_face(std::uint32_t g, std::span<const Window> arriving);
  void schedule(std::uint32_t h);
  void emit(std::uint32_t v);
  void emit_everywhere(std::uint32_t u);
  void emit_lowered_pseudo_source();
  void drain();
  void cross(std::uint32_t h);
  std::span<const Window> list_to_cross(std::uint32_t h, unsigned thread, GeodesicStats& stats);
  // Rule 2 pays where a list gathered windows from several crossings (or pseudo-sources): their runs
  // overlap, and a window is often beaten by one of another run. The windows of one crossing come from a
  // list pruned before it crossed or from one run again, and walking them cost more than the few windows it
  // removed saved (docs/performance.md): such a list crosses as it is.
  bool worth_pruning(const WindowLists::List& list) const { return options_.rule23 && list.runs > 1; }
  std::uint64_t cross_list(std::uint32_t h, std::span<const Window> incoming, std::vector<double>& splits,
                           std::vector<Window>& to_ac, std::vector<Window>& to_bc, ApexReach& reach,
                           Arrival& at_apex) const;
  void deliver(std::uint32_t side, std::vector<Window>& windows, std::uint32_t origin, bool prime);
  void keep_entering(std::uint32_t h, std::span<const Window> list, unsigned thread);

  Handover hand_over(std::uint32_t side, std::span<Window> windows, std::uint32_t origin, bool prime) const;
  void place_new_window(std::uint32_t g, const Window& w);

  void evaluate_targets(std::uint32_t h, std::span<const Window> list);
  void evaluate_targets_from_corners(std::uint32_t face);
  void update_cutoff();

  const SurfaceMesh& mesh_;
  GeodesicOptions options_;
  std::function<void(double)> progress_;
  GeodesicStats stats_;
  EngineState state_;
  std::vector<SourceSite> sources_;
  unsigned threads_ = 1;  // of the run
  std::uint32_t iteration_ = 0;
  bool face_sorted_ = false, order_preserving_ = false;
  WavefrontQueue vertex_queue_;               // vertex-sorted variants
  WavefrontQueue face_queue_;                 // face-sorted variants
  std::vector<std::uint32_t> faces_to_join_;  // face-sorted: per surface vertex, its faces not yet joined
  // Lists scheduled to cross, first in first out: those before pending_front_ have crossed. Emptied whenever
  // every one has, so it holds what one vertex sets moving.
  std::vector<std::uint32_t> pending_;
  std::size_t pending_front_ = 0;
  std::vector<std::uint32_t> emit_queue_;
  std::vector<Window> to_ac_, to_bc_;
  std::vector<double> splits_, key_splits_;
  // With threads above 1 (vertex-sorted): the thread team, kept from run to run, and the bands.
  std::unique_ptr<ParallelPropagation> parallel_;

  // The surface vertices the last run reached. A run that stops early (a cut-off, near targets, a pair search)
  // changes only what lies around them, and the next run resets just that (reset_reached), so that it costs
  // what it reaches rather than the mesh's size. Complete only after a one-thread vertex-sorted run that
  // ended normally; otherwise, or when it lists more than a share of the vertices, the next run resets all.
  std::vector<std::uint32_t> reached_;
  bool reached_complete_ = false;
  static constexpr std::uint32_t kResetAllFromShare = 8;  // a run reaching more than 1/8 of the vertices

  // The largest distance the last run answers: the cut-off, and where the targets lowered it below
  // max_distance, the farthest target's distance plus the prune tolerance (every path that short was
  // followed: windows and emissions stop only beyond it). A vertex as far as that target (a copy of its
  // vertex, its mirror image on a symmetric mesh) may be reached along another way whose rounding puts it a
  // few ulps farther, and one thread and several round differently: without the tolerance it would be
  // answered or not by the rounding of the way that reached it.
  double answered_up_to_ = HUGE_VAL;
  bool targets_changed_ = false;               // since update_cutoff: the farthest target may have changed
  bool goal_directed_ = false;                 // asked for (set_goal_directed)
  std::unique_ptr<FaceWindows> kept_windows_;  // with keep_windows: every list crossing a face, logged
};

// The shortest path of the engine's last run to its target `target`, whose distance is finite (path.cpp): to a
// target at a vertex, through the copy of that input vertex with the smallest distance.
GeodesicPath trace_to_target(const Mesh& mesh, const VtpEngine& engine, std::size_t target);

}  // namespace exactgeo::detail
