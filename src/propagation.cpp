#include "propagation.hpp"

#include <algorithm>
#include <cmath>

namespace exactgeo::detail {
namespace {

// Whether sqrt(dx^2 + dy_squared) > bound, without the square root (bound may be +inf).
bool longer_than(double dx, double dy_squared, double bound) { return bound < 0 || dx * dx + dy_squared > bound * bound; }

// Where the line from the pseudo-source through C meets AB (paper Section 4.1). When both lie on AB's line
// (a flat triangle and a pseudo-source on the edge) every ray runs along AB; any split point is as good.
double apex_split(const Window& w, const FaceFrame& f) {
  const double rise = f.apex_y - w.py;
  if (!(rise > 0)) return w.b1;
  return w.px + (f.apex_x - w.px) * (-w.py / rise);
}

// A ray from (px, py) through (x, 0) continues across the triangle; returns where it meets the edge that
// leaves the origin in direction (cos_angle, sin_angle), as a distance from the origin clamped to [0, length].
double hit_side(double px, double py, double x, double cos_angle, double sin_angle, double side_length) {
  const double denominator = py * cos_angle + sin_angle * (x - px);
  double u;
  if (denominator < 0)
    u = py * x / denominator;
  else
    u = x > 0 ? side_length : 0;  // parallel or receding: the ray reaches the side's far end at the limit
  return std::clamp(u, 0.0, side_length);
}

// Removes the part of `w` that the vertex at x = 0 with distance d_start, or the vertex at x = length with
// distance d_end, reaches more cheaply along the edge (Case 12). Returns false if nothing is left.
// Near the start vertex the excess D_w(x) - d_start - x is non-increasing in x, near the end vertex
// D_w(x) - d_end - (length - x) is non-decreasing, so each check removes a prefix or a suffix. A whole
// window goes only when beaten by more than the tolerance; a part of it is cut at the exact tie point, so
// that windows tying with a vertex path cannot circulate for ever around zero-area faces.
[[gnu::always_inline]] inline bool check_with_vertices(Window& w, double length, double d_start, double d_end, const Tolerances& tol) {
  // A pseudo-source on the edge's line sees the window under a zero angle: only a degenerate (zero-area)
  // face lets rays run along an edge, and their distances are those of the path through the edge's end.
  if (!(w.py < -tol.min_width)) return false;
  // Most windows are beaten nowhere: each test compares squared lengths, so a kept window costs no sqrt.
  const double py_squared = w.py * w.py;
  auto exceeds = [&](double x, double bound) { return longer_than(x - w.px, py_squared, bound - w.sigma); };
  if (exceeds(w.b1, d_start + w.b1 + tol.prune)) return false;
  if (exceeds(w.b0, d_end + (length - w.b0) + tol.prune)) return false;
  if (exceeds(w.b0, d_start + w.b0 + tol.prune)) {
    // Solve sigma + r(x) = d_start + x; written without the cancellation of (px^2 + py^2 - k^2) / 2(px + k).
    const double k = d_start - w.sigma;
    if (!(w.px + k > 0)) return false;  // r(x) > x + k everywhere: the start vertex wins the whole window
    const double tie = 0.5 * (w.px - k) + py_squared / (2 * (w.px + k));
    w.b0 = std::max(w.b0, std::min(tie, w.b1));
  }
  if (exceeds(w.b1, d_end + (length - w.b1) + tol.prune)) {
    const double k = d_end + length - w.sigma;  // solve sigma + r(x) = d_end + length - x
    if (!(k - w.px > 0)) return false;
    const double tie = 0.5 * (k + w.px) - py_squared / (2 * (k - w.px));
    w.b1 = std::min(w.b1, std::max(tie, w.b0));
  }
  return w.b1 - w.b0 > tol.min_width;
}

// Crosses the part [x0, x1] of `w` to the side leaving the origin at the given angle. The frame is AB's, or
// its mirror image (x -> length - x) for the side BC. Rays that leave through that side have their
// pseudo-source on the triangle's side of it: rotated below it up to `rounding`, then clamped there.
[[gnu::always_inline]] inline Window cross_to_side(const Window& w, double px, double x0, double x1, double cos_angle, double sin_angle,
                     double side_length, [[maybe_unused]] double rounding) {
  Window out;
  out.b0 = hit_side(px, w.py, x0, cos_angle, sin_angle, side_length);
  out.b1 = hit_side(px, w.py, x1, cos_angle, sin_angle, side_length);
  // Rotate by -angle: the side becomes the x axis, the triangle (and the pseudo-source) lie below it.
  out.px = px * cos_angle + w.py * sin_angle;
  const double y = w.py * cos_angle - px * sin_angle;
  EXACTGEO_ASSERT(y <= rounding);
  out.py = std::min(y, 0.0);
  out.sigma = w.sigma;
  out.pseudo_source = w.pseudo_source;
  return out;
}

// The cosine of the angle between the edge and a window's ray to edge point x, given the ray's length r. A
// ray of zero length (pseudo-source on the edge) has no direction: any cosine in [-1, 1] is possible.
double ray_cosine(const Window& w, double x, double r) { return r > 0 ? (x - w.px) / r : std::nan(""); }

// True if a function on [0, span] with the given end values and slope within [min_slope, max_slope] stays
// above `floor` everywhere (NaN slopes prove nothing).
bool stays_above(double at_start, double at_end, double min_slope, double max_slope, double span, double floor) {
  if (!(at_start > floor && at_end > floor)) return false;
  if (min_slope >= 0 || max_slope <= 0) return true;  // monotone: the smaller end is the minimum
  if (!(max_slope - min_slope > 0)) return false;
  // Lowest point allowed: where the line falling from the start at min_slope meets the line rising to the
  // end at max_slope.
  const double t = (at_start - at_end + max_slope * span) / (max_slope - min_slope);
  return at_start + min_slope * std::clamp(t, 0.0, span) > floor;
}

// Whether the rays of window w between its point e and its end `end` are beaten through window v's path to
// e, e being a point of both windows on their edge: true if that path meets w's ray to `end` (both segments,
// ends included). Used for Rule 2, e an end of the windows' overlap (the 2016 code's pairwise cases). The
// caller checks that v is shorter at e by more than the tolerance; then the rays are beaten:
// The rays of w form a flat fan without vertices inside, and e lies in it, so inside that fan v's path is
// the straight line back from e: if it meets w's ray through `end` at Y, Y is one surface point on both
// paths, and so is every point where v's path crosses the rays of w between e and `end`. Along v's path
// towards e the excess D_w - D_v can only fall (|Y - p_v| grows at rate 1, |Y - p_w| at most as fast), so
// if v is shorter at e by more than the tolerance, it is at every such crossing, and each of those rays of
// w is beaten beyond it by v's path to the crossing followed by the rest of the ray. This holds past the
// end of v's own window too, where pairwise trimming cannot reach.
// The intersection's parameters are compared with the denominator instead of divided: this runs often.
bool crossing_beats_rays(const Window& w, double end, const Window& v, double e) {
  const double sx = e - v.px, sy = -v.py;    // v's path: p_v + u (sx, sy), u in [0, 1]
  const double rx = end - w.px, ry = -w.py;  // w's ray: p_w + t (rx, ry), t in [0, 1]
  double denominator = rx * sy - ry * sx;
  const double cx = v.px - w.px, cy = v.py - w.py;
  double t = cx * sy - cy * sx, u = cx * ry - cy * rx;  // times the denominator
  if (denominator < 0) {
    denominator = -denominator;
    t = -t;
    u = -u;
  }
  return denominator > 0 && t >= 0 && t <= denominator && u >= 0 && u <= denominator;
}

// `loser` is longer than `winner` by more than the tolerance over their whole overlap [lo, hi]. Its parts past
// the overlap are beaten too if its rays there cross the winner's path to the overlap's end on that side
// (crossing_beats_rays): comparing the windows where both reach cannot see that.
// Returns true if nothing of the loser is left; otherwise cuts the beaten parts off (the rest of it, in the
// overlap, is for trimming to take).
bool beaten_past_overlap(Window& loser, const Window& winner, double lo, double hi, double min_width) {
  const bool left = loser.b0 < lo - min_width, right = loser.b1 > hi + min_width;
  const bool left_beaten = left && crossing_beats_rays(loser, loser.b0, winner, lo);
  const bool right_beaten = right && crossing_beats_rays(loser, loser.b1, winner, hi);
  if ((!left || left_beaten) && (!right || right_beaten)) return true;
  if (left_beaten) loser.b0 = lo;
  if (right_beaten) loser.b1 = hi;
  return false;
}

enum class Removed { none, first, second };

// Over the overlap of `first` and `second` (same edge, same side): if one is longer than the other by more
// than the tolerance throughout, the loser loses its end pieces inside the overlap, and past it where
// beaten_past_overlap says; it is removed if nothing is left. Sound for any pair: a point of the overlap is
// reached by both, so a ray of the loser through it is beaten by the winner's path to that point followed by
// the same ray. Two windows that agree to within the tolerance both stay: dropping one of them (the second)
// lost a path by 3e-14 of the largest distance on the bunny, and such ties are a few thousand of a run's
// overlaps, so keeping both costs no measurable time.
// Where the two distances cross inside the overlap, each window keeps its side of the crossing if the two
// have the same distance at their pseudo-sources (two unfoldings of one pseudo-source, most often): the
// crossing is then where the perpendicular bisector of the pseudo-sources meets the edge, one division.
// Otherwise both stay whole. Cutting those too (the roots of a quadratic, polished) narrowed them, but cost
// more than the narrower windows saved: the whole run was 7-10% slower on nefertiti.
// It and keep_if_not_beaten stay inlined in the pruning walk: every split into out-of-line calls measured
// 2-8% slower over a whole run.
[[gnu::always_inline]] inline Removed resolve_overlap(Window& first, Window& second, const Tolerances& tol) {
  const double lo = std::max(first.b0, second.b0), hi = std::min(first.b1, second.b1);
  if (!(hi - lo > tol.min_width)) return Removed::none;
  const double span = hi - lo;
  const double first_lo = length(lo - first.px, first.py), first_hi = length(hi - first.px, first.py);
  const double second_lo = length(lo - second.px, second.py), second_hi = length(hi - second.px, second.py);
  const double difference_lo = second.sigma + second_lo - (first.sigma + first_lo);
  const double difference_hi = second.sigma + second_hi - (first.sigma + first_hi);
  // Each case below the crossing needs the difference on the same side of the tolerance band at both ends.
  // Most overlapping pairs cross, and are done here.
  auto side_of_band = [&](double d) { return d > tol.prune ? 1 : (d < -tol.prune ? -1 : 0); };
  const int side = side_of_band(difference_lo), side_at_hi = side_of_band(difference_hi);
  if (side != side_at_hi) {
    if (side * side_at_hi < 0 && first.sigma == second.sigma) {
      // r1 = r2 squared is linear in x (measured from lo, for conditioning); equal x of the pseudo-sources
      // would leave the difference one sign, which the ends rule out.
      const double p1x = first.px - lo, p2x = second.px - lo;
      const double crossing = (p2x * p2x + second.py * second.py - p1x * p1x - first.py * first.py) / (2 * (p2x - p1x));
      if (crossing > 0 && crossing < span) {
        Window& loser_at_lo = side > 0 ? second : first;
        Window& loser_at_hi = side > 0 ? first : second;
        if (loser_at_lo.b0 >= lo) loser_at_lo.b0 = lo + crossing;
        if (loser_at_hi.b1 <= hi) loser_at_hi.b1 = lo + crossing;
        if (!(second.b1 - second.b0 > tol.min_width)) return Removed::second;
        if (!(first.b1 - first.b0 > tol.min_width)) return Removed::first;
      }
    }
    return Removed::none;
  }
  // The slope of second - first is cos(theta2) - cos(theta1), each cosine increasing along the edge, so it
  // lies in [cos(theta2) at lo - cos(theta1) at hi, cos(theta2) at hi - cos(theta1) at lo]: with the ends'
  // values that bounds the difference over the whole overlap.
  const double min_slope = ray_cosine(second, lo, second_lo) - ray_cosine(first, hi, first_hi);
  const double max_slope = ray_cosine(second, hi, second_hi) - ray_cosine(first, lo, first_lo);
  Window* loser;
  if (side > 0 && stays_above(difference_lo, difference_hi, min_slope, max_slope, span, tol.prune)) {
    if (beaten_past_overlap(second, first, lo, hi, tol.min_width)) return Removed::second;
    loser = &second;
  } else if (side < 0 && stays_above(-difference_lo, -difference_hi, -max_slope, -min_slope, span, tol.prune)) {
    if (beaten_past_overlap(first, second, lo, hi, tol.min_width)) return Removed::first;
    loser = &first;
  } else {
    return Removed::none;
  }
  // Only an end of the loser that lies in the overlap can go: a window stays one interval.
  const Removed loser_removed = loser == &first ? Removed::first : Removed::second;
  const bool starts_in = loser->b0 >= lo, ends_in = loser->b1 <= hi;
  if (starts_in && ends_in) return loser_removed;
  if (starts_in) loser->b0 = hi;
  if (ends_in) loser->b1 = lo;
  return loser->b1 - loser->b0 > tol.min_width ? Removed::none : loser_removed;
}

// One step of the Rule 2 walk: checks windows[i] against the kept windows windows[0, count), from the last
// backwards while those get removed, then keeps it (moving it down to position count) unless it was
// removed itself.
[[gnu::always_inline]] inline void keep_if_not_beaten(std::span<Window> windows, std::size_t& count, std::size_t i,
                                                     const Tolerances& tol) {
  Window& incoming = windows[i];  // count <= i: the kept windows never reach it
  while (count > 0) {
    const Removed removed = resolve_overlap(windows[count - 1], incoming, tol);
    if (removed == Removed::second) return;
    if (removed == Removed::none) break;
    --count;
  }
  if (count != i) windows[count] = incoming;
  ++count;
}

}  // namespace

ApexReach reach_apex(std::span<const Window> list, const FaceFrame& frame, std::vector<double>& splits,
                     double prune_tolerance) {
  EXACTGEO_ASSERT(!list.empty());
  // Two passes, so that the divisions and square roots of different windows overlap in the pipeline
  // instead of queuing behind the running minimum.
  splits.resize(list.size());
  for (std::size_t i = 0; i < list.size(); ++i) splits[i] = apex_split(list[i], frame);
  ApexReach best{HUGE_VAL, kNone, 0, true};
  double runner_up = HUGE_VAL;  // the shortest way to C through any window but the best
  for (std::uint32_t i = 0; i < list.size(); ++i) {
    // The shortest path to C through the window: straight if C is visible through it (then the clamped
    // split point lies on the straight line), otherwise bent at the nearer end.
    const Window& w = list[i];
    // No path through w is shorter than the straight line from its pseudo-source: skip windows whose
    // line is clearly longer than the best path so far by more than the prune tolerance (the relative
    // margin covers the rounding of `distance`); those cannot rival it.
    const double room = best.distance * (1 + 1e-14) + prune_tolerance - w.sigma;
    const double to_apex_x = frame.apex_x - w.px, to_apex_y = frame.apex_y - w.py;
    if (!(room > 0) || to_apex_x * to_apex_x + to_apex_y * to_apex_y > room * room) continue;
    const double crossing = std::clamp(splits[i], w.b0, w.b1);
    const double distance = w.sigma + length(crossing - w.px, w.py) + length(frame.apex_x - crossing, frame.apex_y);
    if (distance < best.distance) {
      runner_up = best.distance;
      best = {distance, i, crossing, true};
    } else {
      runner_up = std::min(runner_up, distance);
    }
  }
  best.unrivalled = runner_up > best.distance + prune_tolerance;
  return best;
}

std::uint64_t cross_face(std::span<const Window> list, std::span<const double> splits, const FaceFrame& f,
                         const ApexReach& reach, bool rule1, const CornerDistances& corners, SideExit ac_exit,
                         SideExit bc_exit, const Tolerances& tol, std::vector<Window>& to_ac,
                         std::vector<Window>& to_bc) {
  const double length_ac_frame = length(f.apex_x, f.apex_y);
  const double length_bc_frame = length(f.length - f.apex_x, f.apex_y);
  // Direction of AC from A, and of BC from B in the mirrored frame; a zero-length side has no direction.
  const double cos_a = length_ac_frame > 0 ? f.apex_x / length_ac_frame : 1, sin_a = length_ac_frame > 0 ? f.apex_y / length_ac_frame : 0;
  const double cos_b = length_bc_frame > 0 ? (f.length - f.apex_x) / length_bc_frame : 1,
               sin_b = length_bc_frame > 0 ? f.apex_y / length_bc_frame : 0;
  EXACTGEO_ASSERT(splits.size() == list.size() && reach.window < list.size());
  std::uint64_t propagations = 0;
  const std::size_t ac_begin = to_ac.size(), bc_begin = to_bc.size();
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Window& w = list[i];
    // Rays left of the split point reach AC, rays right of it reach BC. Rule 1 (paper Proposition 4.1, in a
    // form that is sound for every ray): a ray entering left of the list's separating point s that would
    // reach BC must cross w_s's path s -> C inside the triangle, where w_s's path is shorter by more than the
    // prune tolerance when every other window reaches C longer by more than that (else this window would
    // reach C within it); likewise for rays entering right of s that would reach AC. Where another window
    // reaches C within the tolerance, the rays stay: which of the two is best is then rounding.
    // (The 2016 code also drops the rays of a window straddling s on s's far side when they cross w_s's path
    // behind the edge. In a sound form that saved 0.5% of the propagations once Rule 2 walked whole lists,
    // and the run took 5% longer with it.)
    double left_end = std::min(w.b1, splits[i]), right_start = std::max(w.b0, splits[i]);
    if (rule1 && reach.unrivalled) {
      left_end = std::min(left_end, reach.separating_point);
      right_start = std::max(right_start, reach.separating_point);
    }
    // A piece leaving through a boundary side counts as propagated, but there is nothing to compute: its
    // rays leave the surface. A piece that ends at the split point ends at C on its side: computed, the ray
    // through the split point could meet the side short of C where the pseudo-source lies a hair from AB's
    // line (a near-sliver's corner), by rounding over that height (1e-5 of the side at 6e-13), and the rays
    // between would reach nothing.
    if (left_end - w.b0 > tol.min_width) {
      ++propagations;
      Window out = cross_to_side(w, w.px, w.b0, left_end, cos_a, sin_a, f.length_ac, tol.min_width);
      if (left_end == splits[i]) out.b1 = f.length_ac;
      if (ac_exit.open && check_with_vertices(out, f.length_ac, corners.a, corners.c, tol))
        to_ac.push_back(to_twin_frame(out, f.length_ac, ac_exit.reversed));
    }
    if (w.b1 - right_start > tol.min_width) {
      ++propagations;
      // Mirror x -> length - x so that B is the origin; the piece's ends swap.
      Window out = cross_to_side(w, f.length - w.px, f.length - w.b1, f.length - right_start, cos_b, sin_b,
                                 f.length_bc, tol.min_width);
      if (right_start == splits[i]) out.b1 = f.length_bc;
      if (bc_exit.open && check_with_vertices(out, f.length_bc, corners.b, corners.c, tol))
        to_bc.push_back(to_twin_frame(out, f.length_bc, bc_exit.reversed));
    }
  }
  // Keep each output list ordered along its edge, so that neighbours in the list are neighbours on the edge.
  // Windows reach AC in the order of their position on AB as seen from A, and BC in the reverse order as seen
  // from B: on a consistently oriented mesh the frame across BC runs from C, and that order is kept.
  if (ac_exit.reversed) std::reverse(to_ac.begin() + static_cast<std::ptrdiff_t>(ac_begin), to_ac.end());
  if (!bc_exit.reversed) std::reverse(to_bc.begin() + static_cast<std::ptrdiff_t>(bc_begin), to_bc.end());
  return propagations;
}

std::size_t prune_list(std::span<Window> windows, const Tolerances& tol) {
  // Insertion by start: the list is a few runs, each in order already, so most windows stay where they are.
  for (std::size_t i = 1; i < windows.size(); ++i)
    if (windows[i].b0 < windows[i - 1].b0) insert_in_order(windows.first(i + 1), i);
  std::size_t count = 0;  // the kept windows form a prefix of the span: it never grows past the read position
  for (std::size_t i = 0; i < windows.size(); ++i) keep_if_not_beaten(windows, count, i, tol);
  return count;
}

}  // namespace exactgeo::detail
