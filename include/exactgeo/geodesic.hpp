// Exact geodesic distances on a triangle mesh with the VTP algorithm (Qin et al., SIGGRAPH 2016).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <stop_token>
#include <string_view>
#include <utility>
#include <vector>

#include "exactgeo/export.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/surface_point.hpp"

namespace exactgeo {

namespace detail {
class VtpEngine;
class FaceWindows;
struct SourceSite;
}

// The paper's variants (Section 5): all exact, they differ in speed and in how many windows they propagate.
enum class Algorithm {
  vtp,    // vertex-sorted wavefront, order-free secondary merge (the paper's final algorithm)
  opvtp,  // vertex-sorted wavefront, order-preserving secondary merge (binary-search insertion)
  ftp,    // face-sorted wavefront (one triangle per iteration), order-free secondary merge
  opftp,  // face-sorted wavefront, order-preserving secondary merge
};

// Threads worth giving one run on this mesh (GeodesicOptions::threads): one per 10,000 faces, up to one per
// core, so that each thread's share of the work pays for its synchronisation (1 below 20,000 faces). The
// command line's and the Python package's default; the library's stays 1.
EXACTGEO_API unsigned recommended_threads(const Mesh& mesh);

// Names as used by the command line and the Python package, in the enum's order.
inline constexpr std::array<std::pair<Algorithm, std::string_view>, 4> kAlgorithmNames = {{
    {Algorithm::vtp, "vtp"},
    {Algorithm::opvtp, "opvtp"},
    {Algorithm::ftp, "ftp"},
    {Algorithm::opftp, "opftp"},
}};
EXACTGEO_API std::string_view algorithm_name(Algorithm algorithm);
// Throws exactgeo::Error(invalid_argument) listing the known names.
EXACTGEO_API Algorithm parse_algorithm(std::string_view name);

// How a run goes. Each value field's meaning is in for_each_option_field below; all give the same distances.
struct GeodesicOptions {
  Algorithm algorithm = Algorithm::vtp;
  bool rule1 = true;
  bool rule23 = true;
  double max_distance = std::numeric_limits<double>::infinity();
  bool collect_timings = false;
  unsigned threads = 1;
  bool keep_windows = false;
  // A run whose token is stopped (std::stop_source::request_stop, from any thread) ends within a few
  // milliseconds by throwing exactgeo::Error(cancelled). Distance matrices and sampling pass it to every run.
  // A handle rather than a setting, so not among the fields below.
  std::stop_token stop{};
};

// Every setting of GeodesicOptions in declaration order, with what it means: calls
// visit(name, member pointer, description) once per field. The Python options are generated from it.
template <class Visit>
constexpr void for_each_option_field(Visit&& visit) {
  using O = GeodesicOptions;
  visit("algorithm", &O::algorithm, "the paper's variant (Section 5), see kAlgorithmNames; vtp is its final algorithm");
  visit("rule1", &O::rule1,
        "Rule 1 \"One Angle Two Sides\" (Section 4.1): prune with the window list's separating point; off, every "
        "window covering the opposite vertex is split in two");
  visit("rule23", &O::rule23, "Rules 2 and 3 (Sections 4.2-4.3): pairwise checks between neighbouring windows");
  visit("max_distance", &O::max_distance,
        "distances above this are not computed (+inf) and the wavefront stops there, so the work shrinks with "
        "the radius; not negative or NaN");
  visit("collect_timings", &O::collect_timings,
        "split the time into window propagation, pruning and queue (GeodesicStats); the clock reads slow the run "
        "down by up to 60%");
  visit("threads", &O::threads,
        "threads sharing one run: 1 runs the sequential engine; 0 takes one per core; from 2 on the wavefront "
        "advances in distance bands whose vertices and lists the threads share, with the distances of one "
        "thread to within 1e-14 of the largest (the last bits may change from run to run); face-sorted "
        "variants run on one thread");
  visit("keep_windows", &O::keep_windows,
        "keep, after the run, the windows that reached each face, so that GeodesicSolver::distance_at and "
        "path_to_point answer the exact distance and shortest path to any surface point (GeodesicStats::"
        "kept_window_bytes says what they hold); off, a run keeps nothing beyond its vertices' distances");
}

// What a run did: the counts as the paper defines them (Section 6.2) and the time. A propagation is prime if
// it crosses a triangle that joined the traversed area in the current iteration, secondary if it crosses one
// inside the area. A merge is a list arriving at a wavefront edge that already holds windows: prime on a new
// wavefront edge (Rule 3's PrimeMerge), secondary on an older one (SecondMerge). Each field's meaning is in
// for_each_stats_field below.
struct GeodesicStats {
  std::uint64_t window_propagations = 0;
  std::uint64_t prime_propagations = 0;
  std::uint64_t secondary_propagations = 0;
  std::uint64_t prime_merges = 0;
  std::uint64_t secondary_merges = 0;
  std::uint64_t peak_windows = 0;
  std::uint64_t peak_window_bytes = 0;
  std::uint64_t vertex_pops = 0;
  std::uint64_t face_pops = 0;
  std::uint64_t pseudo_source_emissions = 0;
  std::uint64_t parallel_bands = 0;
  std::uint64_t parallel_critical_path = 0;
  std::uint64_t list_crossings = 0;
  std::uint64_t parallel_lock_waits = 0;
  std::uint64_t kept_windows = 0;
  std::uint64_t kept_window_bytes = 0;
  unsigned threads = 0;
  double propagation_seconds = 0.0;
  double setup_seconds = 0.0;
  double window_propagation_seconds = 0.0;
  double pruning_seconds = 0.0;
  double queue_seconds = 0.0;
  double parallel_seconds = 0.0;
  double parallel_busy_seconds = 0.0;
  double parallel_busiest_thread_seconds = 0.0;
  double parallel_start_seconds = 0.0;
  double parallel_starved_seconds = 0.0;
  double parallel_lock_wait_seconds = 0.0;

  // threads > 1 with collect_timings: one record per band, in order (empty otherwise). Not in the field
  // table below: the command line writes it to its --stats file as columns.
  struct Band {
    std::uint32_t vertices = 0;   // moved inside by the band
    std::uint32_t crossings = 0;  // list crossings in it
    std::uint16_t depth = 0;      // its longest chain of crossings (parallel_critical_path's part)
    double seconds = 0.0;         // wall time of the threads' part
    double busy_seconds = 0.0;    // summed over the threads
  };
  std::vector<Band> band_timeline;
};

// What a field of GeodesicStats holds, for code that prints it.
enum class StatsFieldKind {
  count,
  seconds,
  phase_seconds,  // a part of propagation_seconds, measured only with GeodesicOptions::collect_timings
};

// Every field of GeodesicStats in declaration order, with what it means: calls
// visit(name, member pointer, kind, description) once per field. The command line's JSON and summary and
// the Python class are generated from this list, so a new field reaches them all by being added here.
template <class Visit>
constexpr void for_each_stats_field(Visit&& visit) {
  using S = GeodesicStats;
  constexpr StatsFieldKind count = StatsFieldKind::count, seconds = StatsFieldKind::seconds,
                           phase = StatsFieldKind::phase_seconds;
  visit("window_propagations", &S::window_propagations, count, "windows propagated across a triangle (a split counts twice)");
  visit("prime_propagations", &S::prime_propagations, count, "of which across triangles new to the traversed area");
  visit("secondary_propagations", &S::secondary_propagations, count, "of which across triangles inside the traversed area");
  visit("prime_merges", &S::prime_merges, count, "window lists merged on a new wavefront edge (Rule 3)");
  visit("secondary_merges", &S::secondary_merges, count, "window lists merged on an older wavefront edge");
  visit("peak_windows", &S::peak_windows, count, "most windows alive at once");
  visit("peak_window_bytes", &S::peak_window_bytes, count, "bytes of window storage at its largest (live and reusable)");
  visit("vertex_pops", &S::vertex_pops, count, "wavefront vertices taken from the queue (vertex-sorted variants)");
  visit("face_pops", &S::face_pops, count, "wavefront triangles taken from the queue (face-sorted variants)");
  visit("pseudo_source_emissions", &S::pseudo_source_emissions, count, "saddle or boundary vertices that (re-)emitted windows");
  visit("parallel_bands", &S::parallel_bands, count,
        "threads > 1: distance bands the wavefront advanced by (vertex_pops / parallel_bands per band)");
  visit("parallel_critical_path", &S::parallel_critical_path, count,
        "threads > 1: the longest chain of list crossings in each band, each waiting for the one before, summed "
        "over the bands (the steps no thread count can shorten)");
  visit("list_crossings", &S::list_crossings, count,
        "window lists crossed over a triangle; with threads > 1, against one thread's: "
        "the lists crossed again because more windows joined them, and list_crossings / parallel_critical_path: "
        "the work a step can share");
  visit("parallel_lock_waits", &S::parallel_lock_waits, count,
        "threads > 1: times a thread found a face's or a vertex's lock taken and waited");
  visit("kept_windows", &S::kept_windows, count,
        "keep_windows: windows kept for queries at any point, those that reached a face and that nothing else "
        "beats there (0 without)");
  visit("kept_window_bytes", &S::kept_window_bytes, count,
        "keep_windows: bytes the kept windows and their per-face index hold after the run (0 without)");
  visit("threads", &S::threads, count,
        "threads the run shared: GeodesicOptions::threads, but 1 for the face-sorted variants (sequential), and "
        "fewer where the system would not start them all");
  visit("propagation_seconds", &S::propagation_seconds, seconds, "wall time of the propagation");
  visit("setup_seconds", &S::setup_seconds, seconds,
        "of propagation_seconds, the run's set-up before the first vertex is taken: the per-vertex and per-face "
        "state and the window lists' records, written on the threads (their first touch of fresh memory, most "
        "of it), and with threads > 1 the bands' queue and the locks");
  visit("window_propagation_seconds", &S::window_propagation_seconds, phase,
        "crossing window lists over triangles (0 unless collect_timings)");
  visit("pruning_seconds", &S::pruning_seconds, phase, "pairwise pruning, Rules 2 and 3 (0 unless collect_timings)");
  visit("queue_seconds", &S::queue_seconds, phase, "the wavefront priority queue (0 unless collect_timings)");
  visit("parallel_seconds", &S::parallel_seconds, phase,
        "threads > 1: the part all threads share (each band's emissions, faces and crossings; 0 unless "
        "collect_timings); the rest of propagation_seconds runs on one thread");
  visit("parallel_busy_seconds", &S::parallel_busy_seconds, phase,
        "threads > 1: time the threads spent working in the bands, summed over the threads; threads * "
        "parallel_seconds minus this is the time they waited (0 unless collect_timings)");
  visit("parallel_busiest_thread_seconds", &S::parallel_busiest_thread_seconds, phase,
        "threads > 1: parallel_busy_seconds of the busiest thread (0 unless collect_timings)");
  visit("parallel_start_seconds", &S::parallel_start_seconds, phase,
        "threads > 1: of the waits, from a band's start until each thread joined it, summed (0 unless "
        "collect_timings)");
  visit("parallel_starved_seconds", &S::parallel_starved_seconds, phase,
        "threads > 1: of the waits, threads out of lists waiting for another to hand some over, summed; the "
        "rest is the wait at the bands' ends (0 unless collect_timings)");
  visit("parallel_lock_wait_seconds", &S::parallel_lock_wait_seconds, phase,
        "threads > 1: time spent waiting for locks, summed over the threads; part of parallel_busy_seconds "
        "(0 unless collect_timings)");
}

inline constexpr std::uint32_t kNoSource = std::numeric_limits<std::uint32_t>::max();

struct GeodesicResult {
  // Per input vertex: the distance to the nearest source, +inf where unreachable or beyond the cut-off
  // (max_distance, or the farthest target when targets are given).
  std::vector<double> distances;
  std::vector<std::uint32_t> nearest_source;  // per input vertex: index into the sources, kNoSource if +inf
  std::vector<double> target_distances;       // per target, likewise
  std::vector<std::uint32_t> target_nearest_source;
  GeodesicStats stats;
};

// Where a point of a path lies: on an input vertex, on the edge between two input vertices at parameter t
// (the point (1 - t) * from + t * to), or inside an input triangle.
struct PathPointLocation {
  enum class Kind { vertex, edge, face } kind = Kind::vertex;
  std::uint32_t vertex = 0;                   // Kind::vertex
  std::uint32_t from = 0, to = 0;             // Kind::edge
  double t = 0;                               // Kind::edge
  SurfacePoint face_point;                    // Kind::face
};

// A shortest path from a source to a point: straight inside every face it crosses, bending only at
// vertices. Empty (and length +inf) if the point is unreachable.
struct GeodesicPath {
  std::vector<std::array<double, 3>> points;   // from the source to the point
  std::vector<PathPointLocation> locations;    // one per point
  double length = std::numeric_limits<double>::infinity();
  std::uint32_t source = kNoSource;            // index into the sources
};

// A reusable solver: owns the engine's buffers, so repeated runs on one mesh allocate nothing new, and
// answers path queries about its last run. The mesh must outlive the solver. One solver per thread: a
// solver is not safe to share between threads (a path query answers about whichever run came last), while
// any number of solvers may share one Mesh, which is immutable.
class EXACTGEO_API GeodesicSolver {
 public:
  explicit GeodesicSolver(const Mesh& mesh);
  ~GeodesicSolver();
  GeodesicSolver(GeodesicSolver&&) noexcept;
  GeodesicSolver& operator=(GeodesicSolver&&) noexcept;

  // Propagates from the sources; each input vertex gets the distance to the nearest one. With targets,
  // their distances are computed too and the propagation stops as soon as they are final: vertex distances
  // are then exact up to the farthest target and +inf beyond (a vertex as far as that target, to 1e-12 of the
  // mesh's size, is answered whatever the rounding of the way that reached it). max_distance cuts targets off
  // like vertices (+inf beyond it; the run stops there); without it every target gets its exact distance,
  // however far (what gdist and pygeodesic return whatever their max_distance). A source or target at a corner is that
  // input vertex: a source at each of its surface copies, a target with its distance in `distances` (the
  // smallest over the copies). Throws exactgeo::Error(invalid_argument) naming the offending source, target or
  // option.
  const GeodesicResult& solve(std::span<const SurfacePoint> sources, std::span<const SurfacePoint> targets = {},
                              const GeodesicOptions& options = {});
  // Sources at input vertices. A vertex that the mesh policy split into several surface copies is a
  // source at every copy.
  const GeodesicResult& solve(std::span<const std::uint32_t> source_vertices,
                              std::span<const SurfacePoint> targets = {}, const GeodesicOptions& options = {});
  const GeodesicResult& result() const& { return result_; }
  // The last run's result handed over, not copied (`std::move(solver).result()`), for a caller done with the
  // solver: at a million vertices a copy is some 12 MB more at once. The solver is left as before any run
  // (path and point queries throw until it solves again).
  GeodesicResult result() && {
    GeodesicResult handed = std::move(result_);
    result_ = {};
    return handed;
  }

  // Called now and then during each run, on the calling thread, with the fraction of the mesh's vertices
  // that the wavefront has passed (0 to 1). Empty: no calls.
  void set_progress(std::function<void(double fraction)> callback);

  // The shortest path of the last run from its nearest source to input vertex `vertex`, or to target
  // `target` (an index into the last run's targets).
  GeodesicPath path_to_vertex(std::uint32_t vertex) const;
  GeodesicPath path_to_target(std::size_t target) const;

  // After a run with GeodesicOptions::keep_windows: the distance from the nearest source to each point, as
  // exact as if the points had been the run's targets, +inf where unreachable or beyond the run's cut-off
  // (max_distance, or the farthest target when it had targets). A point at a vertex reads `distances`. Any
  // number of calls, until the next run. Throws exactgeo::Error(invalid_argument) if the last run did not
  // keep its windows, or naming the first invalid point.
  std::vector<double> distance_at(std::span<const SurfacePoint> points) const;
  // The shortest path of the last run (with keep_windows) from its nearest source to the point; empty (length
  // +inf) where distance_at is +inf. Throws like distance_at.
  GeodesicPath path_to_point(const SurfacePoint& point) const;

 private:
  const detail::FaceWindows& kept_windows(const char* query) const;
  const GeodesicResult& run(std::span<const detail::SourceSite> sites, std::span<const SurfacePoint> targets,
                            const GeodesicOptions& options);

  const Mesh* mesh_;
  std::unique_ptr<detail::VtpEngine> engine_;
  GeodesicResult result_;
};

// One-off queries. Distances from one source vertex (an input vertex index). Throws
// exactgeo::Error(invalid_argument) if the index is out of range or names a vertex used by no face.
EXACTGEO_API GeodesicResult geodesic_distance(const Mesh& mesh, std::uint32_t source_vertex, const GeodesicOptions& options = {});

// Distances to the nearest of several source vertices, and which source that is.
EXACTGEO_API GeodesicResult geodesic_distance(const Mesh& mesh, std::span<const std::uint32_t> source_vertices,
                                 const GeodesicOptions& options = {});

// Distances to the nearest of several sources anywhere on the surface.
EXACTGEO_API GeodesicResult geodesic_distance(const Mesh& mesh, std::span<const SurfacePoint> sources,
                                 const GeodesicOptions& options = {});

}  // namespace exactgeo
