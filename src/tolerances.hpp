// Named tolerances of the engine. Exact algorithm, double precision: every comparison that decides what
// to keep errs on the side of keeping, so a tolerance costs work, never a shortest path.
#pragma once

namespace exactgeo::detail {

// Angle excess over 2*pi (interior vertex) or pi (boundary vertex) above which a vertex is a pseudo-source.
// Flat vertices of subdivided meshes sum to 2*pi up to rounding (~1e-15) and are not saddles; a vertex whose
// excess is below this loses at most a wedge of that width, far below the distance accuracy we guarantee.
inline constexpr double kSaddleAngleTolerance = 1e-10;

// Angle by which a pseudo-source's shadow cone (the directions into which paths bend there) is widened on
// each side, so that rounding in the arrival direction (a few ulps of the unfolded coordinates and of the
// corner angles summed around the vertex, far below this) cannot hide a path. No wider: the widened cone
// overlaps the wavefront that passes the vertex straight, and wherever that sliver is wider than
// kMinWindowWidth the two windows are compared again at every later crossing (with 1e-9, those slivers
// made up two thirds of the overlaps Rule 2 resolves on a 100K-face scan, and 15% of its run time). Even
// a gap left by rounding would cost a path only a second-order length: bending across a gap of angle e
// at distance r adds about e^2 r.
inline constexpr double kShadowConeSlack = 1e-13;

// Relative to the mesh's length scale (bounding-box diagonal):
// a window is pruned only if the alternative path is shorter by more than this;
inline constexpr double kPruneTolerance = 1e-12;
// a window narrower than this is dropped (the edge points it covers are within this of its neighbours');
inline constexpr double kMinWindowWidth = 1e-13;
// a vertex reached straight from a pseudo-source nearer than this emits in every direction. The pseudo-source's
// place in a face's frame carries rounding of about 1e-16 of the mesh's size; seen from a vertex that near, the
// ray through the vertex points off by up to 1e-16 of the size over the nearness (1e-4 rad at 1e-12), and the
// windows either side of that ray miss a wedge that wide beyond the vertex, which nothing else reaches where
// the vertex is not a pseudo-source (a source point 1e-12 of an edge from a grid's border vertex made the
// distances beyond it 2.5e-8 too long). The paths through the vertex cover the wedge, longer than the straight
// ones by less than the nearness times the wedge's angle squared: 1e-20 of the size at a nearness of 1e-12,
// less farther out;
inline constexpr double kBesidePseudoSource = 1e-6;
// a pseudo-source re-emits windows only when its distance drops by more than this. Far below
// kPruneTolerance: the windows it sent carry its old distance as they are, so a drop left unsent is an error
// of the distances beyond it. One thread moves a vertex inside once its distance is final and rarely
// lowers it after; the parallel bands move a band's vertices inside together, and on thin triangles
// (aspect 1000:1 and more) a drop below 1e-12 of the length scale, left unsent, put their distances 2.6e-13
// of the largest off one thread's (tests/test_fuzz.cpp, Fuzz.ThinTrianglesOnThreadsAgreeWithOneThread).
// Above rounding: a drop of a few ulps does not send the windows again.
inline constexpr double kReemitTolerance = 1e-15;

// Path tracing snaps a point to a vertex, or ends a piece at its pseudo-source, within this distance.
inline constexpr double kPathSnapTolerance = 1e-10;
// A piece that leads a path away from vertices at one place (path.cpp, leave_coincident) must be as long as
// the distances at its ends say, to within this: a few snapping distances, as both its ends may be snapped.
inline constexpr double kPathPieceTolerance = 4 * kPathSnapTolerance;

// A face whose doubled area is below this times its longest edge squared counts as degenerate.
inline constexpr double kDegenerateAreaRatio = 1e-12;

// Meshes whose extent (the largest side of the bounding box) lies within 2^-this and 2^this are run on as
// given; others on positions scaled by a power of two that brings the extent to [1, 2). The engine squares
// lengths and, in Rule 2's overlap test, multiplies up to six of them: at 2^40 (about 1e12) that is 2^240,
// far from overflow, and features a billion times smaller than the mesh still square to a normal number at
// 2^-40. Scaling by a power of two is exact, so within the range nothing changes, bit for bit.
inline constexpr int kOrdinaryScaleExponent = 40;

}  // namespace exactgeo::detail
