// The binary body of a PLY file, little- or big-endian (see ply_body.hpp): read item after item, or, a large
// body, in blocks of items on the team, whose byte offsets are found first.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "assert.hpp"
#include "ply_body.hpp"

namespace exactgeo::detail {
namespace {

// Reads fixed-size values in the file's byte order; errors name the element item.
class BinaryBody {
 public:
  BinaryBody(const MeshFile& file, std::size_t offset, bool big_endian)
      : file_(file), offset_(offset), swap_(big_endian != (std::endian::native == std::endian::big)) {}

  void begin_item(const PlyElement& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
  }
  double read(PlyType type) {
    const std::size_t size = size_of(type);
    if (file_.bytes.size() - offset_ < size) fail_truncated();
    const char* at = file_.bytes.data() + offset_;
    offset_ += size;
    // clang-format off
    switch (type) {
      case PlyType::int8: return load<std::int8_t>(at);
      case PlyType::uint8: return load<std::uint8_t>(at);
      case PlyType::int16: return load<std::int16_t>(at);
      case PlyType::uint16: return load<std::uint16_t>(at);
      case PlyType::int32: return load<std::int32_t>(at);
      case PlyType::uint32: return load<std::uint32_t>(at);
      case PlyType::float32: return load<float>(at);
      case PlyType::float64: return load<double>(at);
    }
    // clang-format on
    return 0;
  }
  void skip(PlyType type, std::uint64_t count) {
    const std::size_t left = file_.bytes.size() - offset_;  // no overflow below: count <= left and a size <= 8
    if (count > left || count * size_of(type) > left) fail_truncated();
    offset_ += static_cast<std::size_t>(count) * size_of(type);
  }
  // Where the next value starts.
  std::size_t offset() const { return offset_; }
  // Binary items have no rows: their size follows from the header and the list lengths.
  void begin_list(std::int64_t) {}
  void end_item() {}
  [[noreturn]] void fail(const std::string& reason) const {
    throw_file_error(file_, item_name(*element_, index_) + ": " + reason);
  }
  static std::size_t min_bytes(PlyType type) { return size_of(type); }

 private:
  [[noreturn]] void fail_truncated() const { throw_file_error(file_, truncation_reason(*element_, index_)); }

  template <class T>
  double load(const char* at) const {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, at, sizeof(T));
    if (swap_) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    }
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return static_cast<double>(value);
  }

  const MeshFile& file_;
  std::size_t offset_;
  bool swap_;
  const PlyElement* element_ = nullptr;
  std::uint64_t index_ = 0;
};

// A run of one element's items, parsed on its own from its byte offset, and where its triangles start.
struct BinaryBlock {
  const PlyElement* element = nullptr;
  std::uint64_t first_item = 0, end_item = 0;
  std::size_t offset = 0;
  std::uint64_t triangles_before = 0;
};

struct BinaryLayout {
  std::vector<BinaryBlock> blocks;  // in file order
  std::uint64_t vertices = 0;       // the positions the blocks hold
  std::uint64_t triangles = 0;      // the triangles they make
  std::exception_ptr stopped_at;    // the error of the item the blocks end with, where one did not skim
};

// Items per block at least, below which a thread is not worth starting.
constexpr std::size_t kItemGrain = std::size_t{1} << 14;

// Locates the items of a binary body's elements, so that blocks of them can be parsed on the team.
class BinaryLocator {
 public:
  BinaryLocator(const MeshFile& file, const PlyHeader& header, bool big_endian, const ParallelTeam& team)
      : file_(file), header_(header), big_endian_(big_endian), team_(team) {}

  BinaryLayout locate(std::size_t body_offset) const {
    BinaryLayout layout;
    std::size_t offset = body_offset;
    for (const PlyElement& element : header_.elements) {
      // Items without properties take no room, so a huge count of them must not be looped over.
      if (element.properties.empty()) continue;
      if (!locate_items(element, offset, layout)) break;
    }
    return layout;
  }

 private:
  // Cuts an element's items into blocks and finds where each block starts, in bytes and in triangles; moves
  // `offset` past the element. Returns false if an item does not skim: the blocks then end with it, and
  // parsing it raises the file's first error, if no earlier item does.
  bool locate_items(const PlyElement& element, std::size_t& offset, BinaryLayout& layout) const {
    // Every item takes a byte at least: past that many, the file has surely ended.
    const std::uint64_t count = std::min<std::uint64_t>(element.count, file_.bytes.size() - offset + 1);
    if (count == 0) return true;
    const std::size_t blocks = team_.range_count(count, kItemGrain);
    const auto first_of = [&](std::size_t b) { return count * b / blocks; };
    const auto add_block = [&](std::size_t b, std::uint64_t end, std::size_t block_offset, std::uint64_t triangles) {
      layout.blocks.push_back({&element, first_of(b), std::min(first_of(b + 1), end), block_offset, triangles});
    };
    if (const std::optional<UniformItems> uniform = uniform_items(element, offset)) {
      for (std::size_t b = 0; b < blocks; ++b) {
        add_block(b, count, offset + first_of(b) * uniform->bytes, layout.triangles + first_of(b) * uniform->triangles);
      }
      offset += count * uniform->bytes;
      finish(element, count, count * uniform->triangles, layout);
      return true;
    }
    // Items of varying size: one light walk through them finds each block's start.
    BinaryBody body(file_, offset, big_endian_);
    ItemValues values;
    std::uint64_t triangles = 0, end = count;
    for (std::size_t b = 0; b < blocks && !layout.stopped_at; ++b) {
      throw_if_stopped(team_.stop);  // the walk is serial: a stop should not wait for all of it
      add_block(b, end, body.offset(), layout.triangles + triangles);
      for (std::uint64_t item = first_of(b); item < first_of(b + 1); ++item) {
        try {
          triangles += skim_item(body, element, item, header_.vertex_count, values);
        } catch (const Error&) {
          layout.stopped_at = std::current_exception();
          end = item + 1;
          layout.blocks.back().end_item = end;
          break;
        }
      }
    }
    offset = body.offset();
    finish(element, end, triangles, layout);
    return !layout.stopped_at;
  }

  void finish(const PlyElement& element, std::uint64_t items, std::uint64_t triangles, BinaryLayout& layout) const {
    if (element.kind == PlyElementKind::vertex) layout.vertices = items;
    layout.triangles += triangles;
  }

  struct UniformItems {
    std::size_t bytes;
    std::uint64_t triangles;
  };

  // The size and triangles every item of the element has, if all have the first one's (so that where each
  // starts follows from it) and all are in the file: always true of an element without lists, checked on
  // the team otherwise (a mesh of triangles, say).
  std::optional<UniformItems> uniform_items(const PlyElement& element, std::size_t offset) const {
    const auto skim = [&](std::uint64_t item, std::size_t at, ItemValues& values) -> std::optional<UniformItems> {
      BinaryBody body(file_, at, big_endian_);
      try {
        const std::uint64_t triangles = skim_item(body, element, item, header_.vertex_count, values);
        return UniformItems{body.offset() - at, triangles};
      } catch (const Error&) {
        return std::nullopt;
      }
    };
    ItemValues values;
    const std::optional<UniformItems> first = skim(0, offset, values);
    if (!first || element.count > (file_.bytes.size() - offset) / first->bytes) return std::nullopt;
    const auto is_list = [](const PlyProperty& property) { return property.list_count_type.has_value(); };
    if (std::none_of(element.properties.begin(), element.properties.end(), is_list)) return first;
    // An int per range, not a bool: the ranges write their results side by side.
    const int uniform = team_.reduce_ranges(
        element.count - 1, kItemGrain, 1,
        [&](std::size_t begin, std::size_t end) {
          ItemValues range_values;
          for (std::size_t item = begin + 1; item < end + 1; ++item) {
            const std::optional<UniformItems> other = skim(item, offset + item * first->bytes, range_values);
            if (!other || other->bytes != first->bytes || other->triangles != first->triangles) return 0;
          }
          return 1;
        },
        [](int a, int b) { return std::min(a, b); });
    return uniform ? first : std::nullopt;
  }

  const MeshFile& file_;
  const PlyHeader& header_;
  bool big_endian_;
  const ParallelTeam& team_;
};

// A binary body on the team: its items located (BinaryLocator), then each block parsed into its place.
MeshSoup read_binary_body_on_team(const MeshFile& file, const PlyHeader& header, std::size_t body_offset,
                                  bool big_endian, const ParallelTeam& team) {
  const BinaryLayout layout = BinaryLocator(file, header, big_endian, team).locate(body_offset);
  MeshSoup soup;
  resize_on_team(team, soup.positions, 3 * layout.vertices);
  resize_on_team(team, soup.triangles, 3 * layout.triangles);
  for_each_chunk(team, layout.blocks.size(), [&](std::size_t k) {
    const BinaryBlock& block = layout.blocks[k];
    BinaryBody body(file, block.offset, big_endian);
    const bool vertices = block.element->kind == PlyElementKind::vertex;
    SoupWriter sink{vertices ? soup.positions.data() + 3 * block.first_item : nullptr,
                    soup.triangles.data() + 3 * block.triangles_before};
    ItemValues values;
    for (std::uint64_t item = block.first_item; item < block.end_item; ++item) {
      read_item(body, *block.element, item, header.vertex_count, values, sink);
    }
    EXACTGEO_ASSERT(sink.next_triangle ==
                    soup.triangles.data() +
                        3 * (k + 1 < layout.blocks.size() ? layout.blocks[k + 1].triangles_before : layout.triangles));
  });
  // Parsing the item that did not skim fails too, at that item or before: this is only in case it does not.
  if (layout.stopped_at) std::rethrow_exception(layout.stopped_at);
  return soup;
}

}  // namespace

MeshSoup read_binary_body(const MeshFile& file, const PlyHeader& header, std::size_t body_offset,
                          const ParallelTeam& team, std::size_t min_chunk_bytes) {
  const bool big_endian = header.format == PlyFormat::binary_big_endian;
  const std::size_t bytes_left = file.bytes.size() - body_offset;
  if (team.threads() > 1 && bytes_left >= min_chunk_bytes) {
    return read_binary_body_on_team(file, header, body_offset, big_endian, team);
  }
  // A body below a chunk's worth, or one thread: read item after item.
  MeshSoup soup;
  BinaryBody body(file, body_offset, big_endian);
  read_body(body, bytes_left, header, soup);
  return soup;
}

}  // namespace exactgeo::detail
