#include "test_meshes.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <numbers>
#include <numeric>
#include <queue>
#include <sstream>
#include <utility>

#include "exactgeo/io.hpp"
#include "exactgeo/shapes.hpp"

namespace exactgeo_test {
namespace {

const std::filesystem::path kSharedMeshDir = EXACTGEO_SHARED_MESH_DIR;

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

// Faces (that do not repeat a vertex) using each undirected edge.
std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> faces_of_edges(
    const exactgeo::MeshSoup& soup) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> faces;
  for (std::size_t f = 0; f < face_count(soup); ++f) {
    if (repeats_a_vertex(soup, f)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = soup.triangles[3 * f + k], b = soup.triangles[3 * f + (k + 1) % 3];
      faces[{std::min(a, b), std::max(a, b)}].push_back(static_cast<std::uint32_t>(f));
    }
  }
  return faces;
}

}  // namespace

bool shared_meshes_available() { return std::filesystem::is_directory(kSharedMeshDir); }

std::vector<std::string> shared_mesh_names() {
  std::vector<std::string> names;
  if (!shared_meshes_available()) return names;
  for (const auto& entry : std::filesystem::directory_iterator(kSharedMeshDir)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) {
      return static_cast<char>(std::tolower(c));
    });
    if (entry.is_regular_file() &&
        (extension == ".obj" || extension == ".ply" || extension == ".off" || extension == ".stl"))
      names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::optional<exactgeo::MeshSoup> load_shared_mesh(std::string_view name) {
  if (!shared_meshes_available()) return std::nullopt;
  return exactgeo::read_mesh_soup(kSharedMeshDir / std::string(name));
}

Vec3 vertex_position(const exactgeo::MeshSoup& soup, std::uint32_t v) {
  return {soup.positions[3 * v], soup.positions[3 * v + 1], soup.positions[3 * v + 2]};
}

double distance(const Vec3& a, const Vec3& b) { return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

double distance_between(const exactgeo::MeshSoup& soup, std::uint32_t a, std::uint32_t b) {
  return distance(vertex_position(soup, a), vertex_position(soup, b));
}

std::size_t vertex_count(const exactgeo::MeshSoup& soup) { return soup.positions.size() / 3; }
std::size_t face_count(const exactgeo::MeshSoup& soup) { return soup.triangles.size() / 3; }

std::uint32_t add_vertex(exactgeo::MeshSoup& soup, const Vec3& p) {
  soup.positions.insert(soup.positions.end(), p.begin(), p.end());
  return static_cast<std::uint32_t>(vertex_count(soup) - 1);
}

void add_triangle(exactgeo::MeshSoup& soup, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  soup.triangles.insert(soup.triangles.end(), {a, b, c});
}

std::uint32_t vertex_at(const exactgeo::MeshSoup& soup, const Vec3& p) {
  for (std::uint32_t v = 0; v < vertex_count(soup); ++v)
    if (vertex_position(soup, v) == p) return v;
  ADD_FAILURE() << "no vertex at (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return 0;
}

bool repeats_a_vertex(const exactgeo::MeshSoup& soup, std::size_t face) {
  const std::uint32_t* t = &soup.triangles[3 * face];
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
}

std::vector<MeshEdge> unique_edges(const exactgeo::MeshSoup& soup) {
  std::vector<MeshEdge> edges;
  for (const auto& [edge, faces] : faces_of_edges(soup))
    edges.push_back({edge.first, edge.second, static_cast<std::uint32_t>(faces.size())});
  return edges;
}

std::vector<std::uint8_t> non_manifold_vertices(const exactgeo::MeshSoup& soup) {
  // Corners (3 * face + k) around the same vertex are joined when their faces share a two-face edge there.
  UnionFind fans(soup.triangles.size());
  for (const auto& [edge, faces] : faces_of_edges(soup)) {
    if (faces.size() != 2) continue;
    for (std::uint32_t v : {edge.first, edge.second}) {
      std::array<std::uint32_t, 2> corner;
      for (int i = 0; i < 2; ++i)
        for (std::uint32_t k = 0; k < 3; ++k)
          if (soup.triangles[3 * faces[i] + k] == v) corner[i] = 3 * faces[i] + k;
      fans.unite(corner[0], corner[1]);
    }
  }
  std::vector<std::uint32_t> first_fan(vertex_count(soup), UINT32_MAX);
  std::vector<std::uint8_t> split(vertex_count(soup), 0);
  for (std::uint32_t c = 0; c < soup.triangles.size(); ++c) {
    if (repeats_a_vertex(soup, c / 3)) continue;
    const std::uint32_t v = soup.triangles[c], fan = fans.find(c);
    if (first_fan[v] == UINT32_MAX) first_fan[v] = fan;
    if (first_fan[v] != fan) split[v] = 1;
  }
  return split;
}

std::vector<double> edge_graph_dijkstra(const exactgeo::MeshSoup& soup, std::uint32_t source,
                                        std::span<const std::uint8_t> blocked) {
  const std::size_t n = vertex_count(soup);
  std::vector<std::vector<std::pair<std::uint32_t, double>>> neighbours(n);
  for (const MeshEdge& e : unique_edges(soup)) {
    const double length = distance_between(soup, e.low, e.high);
    neighbours[e.low].push_back({e.high, length});
    neighbours[e.high].push_back({e.low, length});
  }
  std::vector<double> d(n, HUGE_VAL);
  using Entry = std::pair<double, std::uint32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  d[source] = 0;
  queue.push({0.0, source});
  while (!queue.empty()) {
    const auto [dv, v] = queue.top();
    queue.pop();
    if (dv > d[v] || (v != source && !blocked.empty() && blocked[v])) continue;
    for (const auto& [w, length] : neighbours[v]) {
      if (dv + length < d[w]) {
        d[w] = dv + length;
        queue.push({d[w], w});
      }
    }
  }
  return d;
}

std::optional<std::uint32_t> first_boundary_vertex(const exactgeo::MeshSoup& soup) {
  for (const auto& [edge, faces] : faces_of_edges(soup))
    if (faces.size() == 1) return edge.first;
  return std::nullopt;
}

exactgeo::SurfacePoint random_face_point(const exactgeo::MeshSoup& soup, Random& random, int zeros) {
  std::uint32_t face;
  do face = random.below(face_count(soup));
  while (repeats_a_vertex(soup, face));
  const double u = random.uniform(0, 1), v = random.uniform(0, 1);
  std::array<double, 3> b = {std::min(u, v), std::max(u, v) - std::min(u, v), 1 - std::max(u, v)};
  if (zeros >= 1) b = {u, 1 - u, 0};  // on an edge
  if (zeros >= 2) b = {1, 0, 0};      // at a corner
  std::rotate(b.begin(), b.begin() + random.below(3), b.end());
  return {face, b};
}

std::uint32_t random_source_vertex(const exactgeo::MeshSoup& soup, std::uint64_t seed) {
  UnionFind pieces(face_count(soup));
  for (const auto& [edge, faces] : faces_of_edges(soup))
    if (faces.size() == 2) pieces.unite(faces[0], faces[1]);
  std::vector<std::uint32_t> size(face_count(soup), 0);
  for (std::uint32_t f = 0; f < face_count(soup); ++f)
    if (!repeats_a_vertex(soup, f)) ++size[pieces.find(f)];
  const auto largest = static_cast<std::uint32_t>(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<std::uint32_t> faces;
  for (std::uint32_t f = 0; f < face_count(soup); ++f)
    if (!repeats_a_vertex(soup, f) && pieces.find(f) == largest) faces.push_back(f);
  Random random(seed);
  const std::uint32_t face = faces[random.below(faces.size())];
  return soup.triangles[3 * face + random.below(3)];
}

exactgeo::MeshSoup random_height_field(Random& random, int nx, int ny, double amplitude, bool smooth) {
  exactgeo::MeshSoup soup = exactgeo::make_grid(nx, ny, 1.0, 1.0);
  struct Wave {
    double kx, ky, phase;
  };
  std::array<Wave, 3> waves;
  for (Wave& wave : waves) wave = {random.uniform(-8, 8), random.uniform(-8, 8), random.uniform(0, 6.3)};
  for (std::size_t v = 0; v < vertex_count(soup); ++v) {
    const double x = soup.positions[3 * v], y = soup.positions[3 * v + 1];
    double z = 0;
    if (smooth) {
      for (const Wave& wave : waves) z += std::sin(wave.kx * x + wave.ky * y + wave.phase) / 3;
    } else {
      z = random.uniform(-1, 1);
    }
    soup.positions[3 * v + 2] = amplitude * z;
  }
  return soup;
}

exactgeo::MeshSoup checkerboard_height_field(int n, double amplitude) {
  exactgeo::MeshSoup soup = exactgeo::make_grid(n, n, 1.0, 1.0);
  for (std::size_t v = 0; v < vertex_count(soup); ++v) {
    const double x = soup.positions[3 * v], y = soup.positions[3 * v + 1];
    soup.positions[3 * v + 2] = amplitude * (std::lround(n * x + n * y) % 2 == 0 ? 1 : -1);
  }
  return soup;
}

exactgeo::MeshSoup random_convex_polygon(Random& random, int sides, int rings) {
  // Gaps between consecutive corners that differ by less than a factor of two stay below pi for 3 or more
  // sides, so the origin is inside: a larger gap would fold the fan over itself.
  std::vector<double> angles(static_cast<std::size_t>(sides));
  double turned = 0;  // the sum of the gaps before each corner, then of all gaps
  for (double& corner : angles) {
    corner = turned;
    turned += random.uniform(1.0, 1.9);
  }
  const double start = random.uniform(0, 2 * std::numbers::pi);
  for (double& corner : angles) corner = start + corner * (2 * std::numbers::pi / turned);
  const double a = random.uniform(0.3, 1.0), b = random.uniform(0.3, 1.0);
  std::vector<double> radii(static_cast<std::size_t>(rings));
  for (double& radius : radii) radius = random.uniform(0.1, 1.0);
  std::sort(radii.begin(), radii.end());
  radii.back() = 1.0;

  exactgeo::MeshSoup soup;
  const std::uint32_t centre = add_vertex(soup, {0, 0, 0});
  for (const double radius : radii)
    for (const double angle : angles) add_vertex(soup, {radius * a * std::cos(angle), radius * b * std::sin(angle), 0});
  const auto n = static_cast<std::uint32_t>(sides);
  const auto corner = [&](std::uint32_t ring, std::uint32_t i) { return 1 + ring * n + i % n; };
  for (std::uint32_t i = 0; i < n; ++i) {
    add_triangle(soup, centre, corner(0, i), corner(0, i + 1));
    for (std::uint32_t ring = 0; ring + 1 < radii.size(); ++ring) {
      add_triangle(soup, corner(ring, i), corner(ring + 1, i), corner(ring + 1, i + 1));
      add_triangle(soup, corner(ring, i), corner(ring + 1, i + 1), corner(ring, i + 1));
    }
  }
  return soup;
}

exactgeo::MeshSoup random_grid_with_holes(Random& random, int nx, int ny, int holes) {
  // Cells are (i, j), 0 <= i < nx, 0 <= j < ny. A hole is a rectangle of cells; `blocked` marks each hole's
  // cells and the ring of cells around it, where no other hole may go.
  std::vector<std::uint8_t> removed(static_cast<std::size_t>(nx * ny), 0), blocked(removed.size(), 0);
  const auto cell = [&](int i, int j) { return static_cast<std::size_t>(j * nx + i); };
  for (int hole = 0; hole < holes && nx >= 3 && ny >= 3; ++hole) {
    const int w = 1 + static_cast<int>(random.below(static_cast<std::size_t>((nx - 1) / 2)));
    const int h = 1 + static_cast<int>(random.below(static_cast<std::size_t>((ny - 1) / 2)));
    if (w > nx - 2 || h > ny - 2) continue;
    const int i0 = 1 + static_cast<int>(random.below(static_cast<std::size_t>(nx - 1 - w)));
    const int j0 = 1 + static_cast<int>(random.below(static_cast<std::size_t>(ny - 1 - h)));
    bool free = true;
    for (int j = j0 - 1; j <= j0 + h; ++j)
      for (int i = i0 - 1; i <= i0 + w; ++i) free = free && !removed[cell(i, j)];
    for (int j = j0; j < j0 + h; ++j)
      for (int i = i0; i < i0 + w; ++i) free = free && !blocked[cell(i, j)];
    if (!free) continue;
    for (int j = j0 - 1; j <= j0 + h; ++j)
      for (int i = i0 - 1; i <= i0 + w; ++i) blocked[cell(i, j)] = 1;
    for (int j = j0; j < j0 + h; ++j)
      for (int i = i0; i < i0 + w; ++i) removed[cell(i, j)] = 1;
  }

  const exactgeo::MeshSoup grid = exactgeo::make_grid(nx, ny, 1.0, 1.0);
  exactgeo::MeshSoup soup{grid.positions, {}};
  const double dx = 1.0 / nx, dy = 1.0 / ny;
  for (std::size_t v = 0; v < vertex_count(soup); ++v) {
    double& x = soup.positions[3 * v];
    double& y = soup.positions[3 * v + 1];
    if (x > 0 && x < 1) x += 0.15 * dx * random.uniform(-1, 1);
    if (y > 0 && y < 1) y += 0.15 * dy * random.uniform(-1, 1);
  }
  // make_grid lists the two triangles of cell (i, j) as faces 2 * (j * nx + i) and the one after.
  for (std::size_t f = 0; f < face_count(grid); ++f)
    if (!removed[f / 2])
      add_triangle(soup, grid.triangles[3 * f], grid.triangles[3 * f + 1], grid.triangles[3 * f + 2]);
  return soup;
}

exactgeo::MeshSoup randomly_rotated(exactgeo::MeshSoup soup, Random& random) {
  // A uniformly random unit quaternion (w, x, y, z), as a rotation matrix.
  double q[4];
  double norm = 0;
  do {
    norm = 0;
    for (double& c : q) {
      c = random.uniform(-1, 1);
      norm += c * c;
    }
  } while (norm > 1 || norm < 1e-3);
  for (double& c : q) c /= std::sqrt(norm);
  const auto [w, x, y, z] = q;
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  for (std::size_t v = 0; v < vertex_count(soup); ++v) {
    const Vec3 p = vertex_position(soup, v);
    for (int k = 0; k < 3; ++k) soup.positions[3 * v + k] = r[k][0] * p[0] + r[k][1] * p[1] + r[k][2] * p[2];
  }
  return soup;
}

namespace {

// Appends `piece` to `glued`; its vertex k becomes soup vertex shared[k], or a new one where that is kNew.
constexpr std::uint32_t kNew = UINT32_MAX;
void glue(GluedPieces& glued, const exactgeo::MeshSoup& piece, std::vector<std::uint32_t> shared) {
  for (std::uint32_t k = 0; k < vertex_count(piece); ++k)
    if (shared[k] == kNew) shared[k] = add_vertex(glued.soup, vertex_position(piece, k));
  for (std::size_t f = 0; f < face_count(piece); ++f)
    add_triangle(glued.soup, shared[piece.triangles[3 * f]], shared[piece.triangles[3 * f + 1]],
                 shared[piece.triangles[3 * f + 2]]);
  glued.pieces.push_back(piece);
  glued.vertex_of.push_back(std::move(shared));
}

int between(Random& random, int lo, int hi) {
  return lo + static_cast<int>(random.below(static_cast<std::size_t>(hi - lo + 1)));
}

}  // namespace

GluedPieces random_bowtie(Random& random, int wings) {
  GluedPieces glued;
  std::uint32_t hub_vertex = kNew;  // in the soup
  for (int wing = 0; wing < wings; ++wing) {
    exactgeo::MeshSoup patch = random_height_field(random, between(random, 1, 4), between(random, 1, 4),
                                                   random.uniform(0.05, 0.5), random.below(2) == 0);
    const std::uint32_t hub = random.below(vertex_count(patch));
    const Vec3 at = vertex_position(patch, hub);
    for (std::size_t i = 0; i < patch.positions.size(); ++i) patch.positions[i] -= at[i % 3];  // hub at 0, exactly
    patch = randomly_rotated(std::move(patch), random);  // which keeps it there
    std::vector<std::uint32_t> shared(vertex_count(patch), kNew);
    shared[hub] = hub_vertex;
    glue(glued, patch, std::move(shared));
    hub_vertex = glued.vertex_of.back()[hub];
  }
  return glued;
}

GluedPieces random_book(Random& random, int pages) {
  GluedPieces glued;
  const int spine_edges = between(random, 1, 4);
  const double spine_length = random.uniform(0.5, 2);
  std::vector<std::uint32_t> spine;  // soup vertices, from the first page
  for (int page = 0; page < pages; ++page) {
    // make_grid's (x, y): x away from the spine (x = 0), y along it; grid vertex (i, j) is j * (columns + 1) + i.
    const int columns = between(random, 1, 4);
    exactgeo::MeshSoup sheet = exactgeo::make_grid(columns, spine_edges, random.uniform(0.5, 2), spine_length);
    const double angle = 2 * std::numbers::pi * (page + random.uniform(-0.2, 0.2)) / pages;
    const Vec3 away = {std::cos(angle), std::sin(angle), 0}, normal = {-std::sin(angle), std::cos(angle), 0};
    const double bumps = random.uniform(0, 0.3);
    for (std::uint32_t v = 0; v < vertex_count(sheet); ++v) {
      const double x = sheet.positions[3 * v], y = sheet.positions[3 * v + 1];
      const double bump = x > 0 ? bumps * random.uniform(-1, 1) : 0;  // the spine stays straight
      for (int k = 0; k < 3; ++k) sheet.positions[3 * v + k] = x * away[k] + bump * normal[k] + (k == 2 ? y : 0);
    }
    std::vector<std::uint32_t> shared(vertex_count(sheet), kNew);
    if (page > 0)
      for (int j = 0; j <= spine_edges; ++j) shared[j * (columns + 1)] = spine[j];
    glue(glued, sheet, std::move(shared));
    if (page == 0)
      for (int j = 0; j <= spine_edges; ++j) spine.push_back(glued.vertex_of.back()[j * (columns + 1)]);
  }
  return glued;
}

exactgeo::MeshSoup random_sheet_with_fin(Random& random) {
  const int nx = between(random, 3, 8), ny = between(random, 3, 8);
  exactgeo::MeshSoup soup = random_height_field(random, nx, ny, random.uniform(0.01, 0.3), random.below(2) == 0);
  // The fin stands on grid row j, an inner row, from column i0 to i1.
  const int j = between(random, 1, ny - 1), i0 = between(random, 0, nx - 1), i1 = between(random, i0 + 1, nx);
  const int levels = between(random, 1, 3);
  const double height = random.uniform(0.1, 1);
  std::vector<std::uint32_t> row_below;
  for (int i = i0; i <= i1; ++i) row_below.push_back(static_cast<std::uint32_t>(j * (nx + 1) + i));
  for (int level = 1; level <= levels; ++level) {
    std::vector<std::uint32_t> row;
    for (const std::uint32_t base : row_below) {
      Vec3 p = vertex_position(soup, base);
      p[1] += 0.05 * random.uniform(-1, 1);  // a bumpy fin, across the row
      p[2] += height / levels;
      row.push_back(add_vertex(soup, p));
    }
    for (std::size_t i = 0; i + 1 < row.size(); ++i) {
      add_triangle(soup, row_below[i], row_below[i + 1], row[i + 1]);
      add_triangle(soup, row_below[i], row[i + 1], row[i]);
    }
    row_below = row;
  }
  return soup;
}

exactgeo::MeshSoup with_coincident_vertices(exactgeo::MeshSoup soup, Random& random, int count,
                                            std::vector<std::uint32_t>& stands_for) {
  stands_for.resize(vertex_count(soup));
  std::iota(stands_for.begin(), stands_for.end(), 0u);
  for (int added = 0; added < count; ++added) {
    const std::vector<std::uint8_t> split = non_manifold_vertices(soup);
    const auto edges = faces_of_edges(soup);
    const auto faces_at = [&](std::uint32_t a, std::uint32_t b) {
      return edges.at({std::min(a, b), std::max(a, b)}).size();
    };
    // Up to a few tries for a corner a of a face (a, b, c), a not split and ab, ac manifold.
    for (int attempt = 0; attempt < 8; ++attempt) {
      const std::size_t face = random.below(face_count(soup));
      const int k = static_cast<int>(random.below(3));
      const std::uint32_t a = soup.triangles[3 * face + k], b = soup.triangles[3 * face + (k + 1) % 3],
                          c = soup.triangles[3 * face + (k + 2) % 3];
      if (split[a] || faces_at(a, b) > 2 || faces_at(a, c) > 2) continue;
      const std::uint32_t a2 = add_vertex(soup, vertex_position(soup, a));
      stands_for.push_back(stands_for[a]);
      if (random.below(3) == 0 && faces_at(a, b) == 1) {
        add_triangle(soup, b, a2, a);  // hanging on the boundary edge ab
      } else {
        soup.triangles[3 * face + k] = a2;
        add_triangle(soup, a, a2, b);
        add_triangle(soup, a2, a, c);
      }
      break;
    }
  }
  return soup;
}

JunctionCase random_junction_case(Random& random) {
  const auto size = [&](int lo, int hi) {
    return lo + static_cast<int>(random.below(static_cast<std::size_t>(hi - lo + 1)));
  };
  JunctionCase c;
  int doubled = size(0, 3);
  switch (random.below(4)) {
    case 0: {
      const int nx = size(1, 8), ny = size(1, 8);
      c.family = "height field " + std::to_string(nx) + "x" + std::to_string(ny);
      exactgeo::MeshSoup field =
          random_height_field(random, nx, ny, std::pow(10.0, random.uniform(-3, 0)), random.below(2) == 0);
      c.glued.vertex_of.emplace_back(vertex_count(field));
      std::iota(c.glued.vertex_of[0].begin(), c.glued.vertex_of[0].end(), 0u);
      c.glued.soup = field;
      c.glued.pieces.push_back(std::move(field));
      doubled = size(1, 6);
      break;
    }
    case 1: {
      const int wings = size(2, 4);
      c.family = "bowtie of " + std::to_string(wings) + " wings";
      c.glued = random_bowtie(random, wings);
      break;
    }
    case 2: {
      const int pages = size(3, 6);
      c.family = "book of " + std::to_string(pages) + " pages";
      c.glued = random_book(random, pages);
      break;
    }
    default:
      c.family = "sheet with a fin";
      c.glued.soup = random_sheet_with_fin(random);
      break;
  }
  c.family += ", " + std::to_string(doubled) + " vertices doubled";
  c.soup = with_coincident_vertices(c.glued.soup, random, doubled, c.stands_for);
  return c;
}

SliverCase random_sliver_case(Random& random, bool near) {
  const int nx = 1 + static_cast<int>(random.below(8)), ny = 1 + static_cast<int>(random.below(8));
  SliverCase c;
  c.field = random_height_field(random, nx, ny, std::pow(10.0, random.uniform(-3, 0)), random.below(2) == 0);
  c.slivers = 1 + static_cast<int>(random.below(6));
  if (near) c.lift = (random.below(2) == 0 ? 1 : -1) * std::pow(10.0, random.uniform(-17, -9));
  c.soup = with_t_junctions(c.field, random, c.slivers, c.lift);
  std::ostringstream family;
  family.precision(17);
  family << "height field " << nx << "x" << ny << ", " << c.slivers;
  if (near)
    family << " near-slivers (lift " << c.lift << ")";
  else
    family << " slivers";
  c.family = family.str();
  return c;
}

exactgeo::MeshSoup with_t_junctions(exactgeo::MeshSoup soup, Random& random, int count, double lift) {
  for (int i = 0; i < count; ++i) {
    const std::size_t face = random.below(face_count(soup));
    const int k = static_cast<int>(random.below(3));
    const std::uint32_t a = soup.triangles[3 * face + k], b = soup.triangles[3 * face + (k + 1) % 3],
                        c = soup.triangles[3 * face + (k + 2) % 3];
    const double t = random.uniform(0.1, 0.9);
    const Vec3 pa = vertex_position(soup, a), pb = vertex_position(soup, b);
    Vec3 at{pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1]), pa[2] + t * (pb[2] - pa[2])};
    if (lift != 0) {
      // Off the line ab along the face's normal, by `lift` of the side's length.
      const Vec3 pc = vertex_position(soup, c);
      const Vec3 ab{pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]}, ac{pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
      const Vec3 normal{ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
      const double scale = lift * std::sqrt(ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]) /
                           std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
      if (std::isfinite(scale))
        for (int i = 0; i < 3; ++i) at[i] += scale * normal[i];
    }
    const std::uint32_t m = add_vertex(soup, at);
    soup.triangles[3 * face + (k + 1) % 3] = m;
    add_triangle(soup, m, b, c);
    add_triangle(soup, a, b, m);
  }
  return soup;
}

double max_finite(std::span<const double> values) {
  double largest = 0;
  for (double x : values)
    if (std::isfinite(x)) largest = std::max(largest, x);
  return largest;
}

testing::AssertionResult distances_match(std::span<const double> actual, std::span<const double> expected,
                                         double relative_tolerance, double* max_relative_error) {
  if (actual.size() != expected.size())
    return testing::AssertionFailure() << "sizes differ: " << actual.size() << " vs " << expected.size();
  const double scale = max_finite(expected);
  double worst = 0;
  std::size_t worst_vertex = 0;
  for (std::size_t v = 0; v < actual.size(); ++v) {
    if (std::isfinite(actual[v]) != std::isfinite(expected[v]))
      return testing::AssertionFailure() << "vertex " << v << ": got " << actual[v] << ", expected " << expected[v];
    if (!std::isfinite(expected[v])) continue;
    const double error = std::abs(actual[v] - expected[v]);
    if (error > worst) {
      worst = error;
      worst_vertex = v;
    }
  }
  const double relative = scale > 0 ? worst / scale : worst;
  if (max_relative_error) *max_relative_error = relative;
  if (relative <= relative_tolerance) return testing::AssertionSuccess();
  std::ostringstream message;
  message.precision(17);
  message << "vertex " << worst_vertex << ": got " << actual[worst_vertex] << ", expected " << expected[worst_vertex]
          << " (error " << relative << " of the largest distance " << scale << ", allowed " << relative_tolerance
          << ")";
  return testing::AssertionFailure() << message.str();
}

std::string variant_label(const exactgeo::GeodesicOptions& options) {
  return std::string(exactgeo::algorithm_name(options.algorithm)) + ", rule1 " + (options.rule1 ? "on" : "off") +
         ", rule23 " + (options.rule23 ? "on" : "off") +
         (options.threads > 1 ? ", " + std::to_string(options.threads) + " threads" : "");
}

std::string variant_name(const testing::TestParamInfo<exactgeo::GeodesicOptions>& info) {
  return std::string(exactgeo::algorithm_name(info.param.algorithm)) + "_Rule1" + (info.param.rule1 ? "On" : "Off") +
         "_Rule23" + (info.param.rule23 ? "On" : "Off") +
         (info.param.threads > 1 ? "_Threads" + std::to_string(info.param.threads) : "");
}

testing::AssertionResult same_run_distances(std::span<const double> actual, std::span<const double> expected,
                                            const exactgeo::GeodesicOptions& options) {
  if (options.threads > 1) return distances_match(actual, expected, 1e-14);
  if (std::equal(actual.begin(), actual.end(), expected.begin(), expected.end())) return testing::AssertionSuccess();
  return distances_match(actual, expected, 0) << " (one thread: expected bit for bit)";
}

}  // namespace exactgeo_test

void exactgeo::PrintTo(const GeodesicOptions& options, std::ostream* out) { *out << exactgeo_test::variant_label(options); }
