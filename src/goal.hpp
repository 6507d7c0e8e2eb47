// The goal of a goal-directed run (docs/pairs.md; VtpEngine::set_goal_directed): the one target, as a point
// in space, and the tests that use the straight line to it as a lower bound on what is left of a path: the
// wavefront's A* key, and the cut-off tests of windows and of pseudo-sources' emissions. Inline: asked for
// every queued vertex and every window handed over.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "propagation.hpp"
#include "surface_mesh.hpp"
#include "windows.hpp"

namespace exactgeo::detail {

// The goal seen from a halfedge's frame: at (x, y), y >= 0, as far from every point of the edge's line as it
// is in space. Unset outside goal-directed runs.
struct GoalAcross {
  double x = 0, y = 0;
  bool set = false;
};

class Goal {
 public:
  // Towards `position` (in the engine's frame), or, unset, no goal: the ordinary run.
  void aim_at(const std::array<double, 3>& position) {
    position_ = position;
    set_ = true;
  }
  void clear() { set_ = false; }
  bool set() const { return set_; }

  // The straight-line distance from surface vertex v to the goal.
  double gap(const SurfaceMesh& mesh, std::uint32_t v) const {
    const std::array<double, 3> p = mesh.position(mesh.surface_to_input[v]);
    const double dx = p[0] - position_[0], dy = p[1] - position_[1], dz = p[2] - position_[2];
    return std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  // The wavefront's order of surface vertex v (or a face, through its vertex v) at distance d: d, plus the
  // straight line to the goal in a goal-directed run (A*).
  double key(const SurfaceMesh& mesh, std::uint32_t v, double d) const { return set_ ? d + gap(mesh, v) : d; }

  // Rotated about the edge's line into halfedge h's plane, on the side away from the pseudo-sources: x along
  // the edge from its tail, y the distance from the line (as a cross product, which keeps it accurate when the
  // goal lies near the line).
  GoalAcross across(const SurfaceMesh& mesh, std::uint32_t h) const {
    if (!set_) return {};
    const std::array<double, 3> a = mesh.position(mesh.surface_to_input[mesh.tail(h)]);
    const std::array<double, 3> b = mesh.position(mesh.surface_to_input[mesh.head(h)]);
    const double length = mesh.halfedges[h].length;
    if (!(length > 0)) return {0.0, gap(mesh, mesh.tail(h)), true};
    const double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double q[3] = {position_[0] - a[0], position_[1] - a[1], position_[2] - a[2]};
    const double c[3] = {e[1] * q[2] - e[2] * q[1], e[2] * q[0] - e[0] * q[2], e[0] * q[1] - e[1] * q[0]};
    return {(e[0] * q[0] + e[1] * q[1] + e[2] * q[2]) / length,
            std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / length, true};
  }

  // Whether a pseudo-source v at distance d cannot lead to anything within the cut-off: in a goal-directed
  // run, every path through v to the goal is at least d plus the straight line from v.
  bool emission_beyond_cutoff(const SurfaceMesh& mesh, std::uint32_t v, double d, double cutoff,
                              double tolerance) const {
    if (!set_) return d > cutoff + tolerance;  // as windows are kept: up to what the run answers
    return cutoff < HUGE_VAL && d + gap(mesh, v) > cutoff + tolerance;
  }

 private:
  std::array<double, 3> position_{};
  bool set_ = false;
};

// A window no point of which lies within the cut-off can only lead further away. In a goal-directed run, a
// window no path through which reaches the goal within the cut-off (docs/pairs.md): a path through edge point
// X = (x, 0) is at least w.sigma + |p - X| long to X and |X - goal| from there, and the sum is smallest where
// the straight line from p (below the edge's line, py <= 0) to the goal unfolded above it crosses the line.
inline bool window_beyond_cutoff(const Window& w, const GoalAcross& goal, double cutoff, double tolerance) {
  if (cutoff == HUGE_VAL) return false;
  if (!goal.set) return w.sigma + length(std::clamp(w.px, w.b0, w.b1) - w.px, w.py) > cutoff + tolerance;
  const double below = -std::abs(w.py);  // |p - X| is the same on either side of the line
  const double rise = goal.y - below;
  const double crossing = rise > 0 ? w.px + (goal.x - w.px) * (-below / rise) : w.px;
  const double x = std::clamp(crossing, w.b0, w.b1);
  return w.sigma + length(x - w.px, below) + length(goal.x - x, goal.y) > cutoff + tolerance;
}

}  // namespace exactgeo::detail
