#include "store_files.hpp"

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <system_error>

namespace exactgeo::store {
namespace {

// The signals that end a run (SIGINT, SIGTERM, SIGHUP) held back for the life of this object: a signal handler
// cannot remove a folder tree (that takes calls that are not async-signal-safe), so one arriving while a file or
// folder is built waits until the building is over, and the builder removes what it built itself. The command has
// no other thread while it writes (the engine's threads are joined before rows are handed over), so no other
// thread takes the signal meanwhile; in Python the interpreter's handler only notes the signal, and the
// KeyboardInterrupt comes once the call returns.
class HeldInterrupts {
 public:
  HeldInterrupts() : outermost_(depth_++ == 0) {
    ::sigemptyset(&held_);
    for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) ::sigaddset(&held_, signal_number);
    ::pthread_sigmask(SIG_BLOCK, &held_, &previous_);
  }
  ~HeldInterrupts() {
    --depth_;
    ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
  }
  HeldInterrupts(const HeldInterrupts&) = delete;
  HeldInterrupts& operator=(const HeldInterrupts&) = delete;

  bool arrived() const {
    sigset_t pending;
    ::sigpending(&pending);
    for (int signal_number : {SIGINT, SIGTERM, SIGHUP})
      if (::sigismember(&pending, signal_number)) return true;
    return false;
  }
  // Lets the held signals in, unless an outer holder (a folder being built around this file) will once its own
  // building is over: the one that arrived is taken now, and its handler runs (the command's ends the run the way
  // the signal would have; Python's notes it, and the KeyboardInterrupt follows the call).
  void deliver() {
    if (outermost_) ::pthread_sigmask(SIG_UNBLOCK, &held_, nullptr);
  }

 private:
  static thread_local int depth_;  // holders alive on this thread
  bool outermost_;
  sigset_t held_{}, previous_{};
};

thread_local int HeldInterrupts::depth_ = 0;

}  // namespace

exactgeo::Error io_error(const std::string& message) { return exactgeo::Error(exactgeo::ErrorCode::io_error, message); }

exactgeo::Error invalid_store(const std::string& message) {
  return exactgeo::Error(exactgeo::ErrorCode::invalid_argument, message);
}

fs::path temporary_beside(const fs::path& final) {
  static thread_local std::mt19937_64 random{std::random_device{}()};
  char suffix[40];
  std::snprintf(suffix, sizeof suffix, ".%ld.%016llx.tmp", static_cast<long>(::getpid()),
                static_cast<unsigned long long>(random()));
  return final.parent_path() / ("." + final.filename().string() + suffix);
}

bool build_folder_into_place(const fs::path& final, Existing existing,
                             const std::function<void(const fs::path&)>& build) {
  const fs::path building = temporary_beside(final);
  std::error_code ignored;
  HeldInterrupts interrupts;
  try {
    fs::create_directories(building);
    build(building);
  } catch (...) {
    fs::remove_all(building, ignored);
    throw;
  }
  if (interrupts.arrived()) {
    fs::remove_all(building, ignored);
    interrupts.deliver();
    throw io_error("interrupted while writing '" + final.string() + "'");  // if the signal's handler returned
  }
  while (std::rename(building.c_str(), final.c_str()) != 0) {
    int reason = errno;
    const bool occupied = reason == EEXIST || reason == ENOTEMPTY;
    if (occupied && existing == Existing::replaced) {
      // Another attempt at the same block may move it aside first (ENOENT): then the rename is tried again.
      const fs::path aside = temporary_beside(final);
      if (std::rename(final.c_str(), aside.c_str()) == 0 || errno == ENOENT) {
        fs::remove_all(aside, ignored);
        continue;
      }
      reason = errno;
    }
    fs::remove_all(building, ignored);
    if (occupied && existing == Existing::kept) return false;
    throw io_error("cannot write '" + final.string() + "': " + std::strerror(reason));
  }
  return true;
}

void write_whole(const fs::path& path, std::span<const unsigned char> bytes) {
  const fs::path writing = temporary_beside(path);
  HeldInterrupts interrupts;
  std::FILE* file = std::fopen(writing.c_str(), "wb");
  if (!file) throw io_error("cannot write '" + path.string() + "': " + std::strerror(errno));
  const bool written = (bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size()) &&
                       std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
  const int reason = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed || std::rename(writing.c_str(), path.c_str()) != 0) {
    const int failure = written && closed ? errno : reason;
    std::remove(writing.c_str());
    throw io_error("error writing '" + path.string() + "': " + std::strerror(failure));
  }
  if (interrupts.arrived()) interrupts.deliver();  // the file is whole: the signal is taken now
}

void write_json_whole(const fs::path& path, const Json& json) {
  const std::string text = json.dump(2);
  write_whole(path, std::span(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

Json group_metadata(const Json& attributes) {
  return Json{{"attributes", attributes}, {"zarr_format", kZarrFormat}, {"node_type", "group"}};
}

void write_group(const fs::path& folder, const Json& attributes) {
  fs::create_directories(folder);
  write_json_whole(folder / "zarr.json", group_metadata(attributes));
}

Json array_metadata(std::span<const std::size_t> shape, std::span<const std::size_t> chunk_shape,
                    std::string_view data_type, const Json& fill_value,
                    const std::vector<std::string>& dimension_names) {
  return Json{
      {"shape", std::vector<std::size_t>(shape.begin(), shape.end())},
      {"data_type", std::string(data_type)},
      {"chunk_grid",
       {{"name", "regular"},
        {"configuration", {{"chunk_shape", std::vector<std::size_t>(chunk_shape.begin(), chunk_shape.end())}}}}},
      {"chunk_key_encoding", {{"name", "default"}, {"configuration", {{"separator", "/"}}}}},
      {"fill_value", fill_value},
      {"codecs", Json::array({{{"name", "bytes"}, {"configuration", {{"endian", "little"}}}}})},
      {"attributes", Json::object()},
      {"dimension_names", dimension_names},
      {"zarr_format", kZarrFormat},
      {"node_type", "array"},
      {"storage_transformers", Json::array()},
  };
}

void write_array(const fs::path& folder, std::span<const std::size_t> shape, std::string_view data_type,
                 const Json& fill_value, const std::vector<std::string>& dimension_names,
                 std::span<const unsigned char> bytes) {
  std::vector<std::size_t> chunk_shape(shape.begin(), shape.end());
  for (std::size_t& size : chunk_shape) size = std::max<std::size_t>(1, size);
  fs::create_directories(folder);
  if (!bytes.empty()) {
    fs::path chunk = folder / "c";  // chunk (0, ..., 0): c/0 for one dimension, c/0/0 for two
    for (std::size_t d = 1; d < shape.size(); ++d) chunk /= "0";
    fs::create_directories(chunk);
    write_whole(chunk / "0", bytes);
  }
  write_json_whole(folder / "zarr.json", array_metadata(shape, chunk_shape, data_type, fill_value, dimension_names));
}

std::optional<Json> read_json(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  Json json = Json::parse(file, nullptr, false);
  if (json.is_discarded()) throw invalid_store("'" + path.string() + "' is not valid JSON");
  if (!json.is_object()) throw invalid_store("'" + path.string() + "' holds " + json.dump() + ", not a JSON object");
  return json;
}

std::string read_json_into(const fs::path& path, Json& json) {
  try {
    const std::optional<Json> read = read_json(path);
    if (!read) return "'" + path.string() + "' is missing";
    json = *read;
  } catch (const exactgeo::Error& e) {
    return e.what();
  }
  return {};
}

std::optional<std::vector<unsigned char>> read_file(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  std::vector<unsigned char> bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  if (file.bad()) return std::nullopt;
  return bytes;
}

std::string array_problem(const fs::path& metadata_path, const Json& metadata, const Json& expected) {
  for (const char* key :
       {"zarr_format", "node_type", "shape", "data_type", "chunk_grid", "chunk_key_encoding", "fill_value", "codecs"}) {
    const Json found = metadata.value(key, Json());
    if (found == expected[key]) continue;
    if (std::string(key) != "codecs")
      return "'" + metadata_path.string() + "': its " + key + " is " + found.dump() + ", not " + expected[key].dump();
    std::string names;
    for (const Json& codec : found.is_array() ? found : Json::array())
      names += (names.empty() ? "" : ", ") + (codec.is_object() ? codec.value("name", std::string("?")) : "?");
    return "'" + metadata_path.parent_path().string() + "': its chunks are stored with codecs [" + names +
           "]; exactgeo writes and reads uncompressed chunks only (codecs [bytes], little-endian)";
  }
  return {};
}

std::string read_whole_array(const fs::path& folder, std::string_view data_type, std::size_t rank, WholeArray& array) {
  const fs::path metadata_path = folder / "zarr.json";
  Json metadata;
  if (std::string problem = read_json_into(metadata_path, metadata); !problem.empty()) return problem;
  const Json shape = metadata.value("shape", Json());
  if (!shape.is_array() || shape.size() != rank ||
      !std::all_of(shape.begin(), shape.end(), [](const Json& size) { return size.is_number_unsigned(); }))
    return "'" + metadata_path.string() + "': its shape is " + shape.dump() + ", not " + std::to_string(rank) +
           " sizes";
  array.shape = shape.get<std::vector<std::size_t>>();
  std::vector<std::size_t> chunks = array.shape;
  for (std::size_t& size : chunks) size = std::max<std::size_t>(1, size);
  const Json layout = array_metadata(array.shape, chunks, data_type, 0, {});
  if (std::string problem = array_problem(metadata_path, metadata, layout); !problem.empty()) return problem;
  std::size_t expected = data_type == "float32" || data_type == "uint32" ? 4 : 8;
  for (std::size_t size : array.shape) expected *= size;
  fs::path chunk = folder / "c";  // chunk (0, ..., 0)
  for (std::size_t d = 0; d < rank; ++d) chunk /= "0";
  std::error_code error;
  if (!fs::exists(chunk, error) && !error) {
    array.bytes.assign(expected, 0);
    return {};
  }
  std::optional<std::vector<unsigned char>> bytes = read_file(chunk);
  if (!bytes) return "'" + chunk.string() + "' cannot be read";
  if (bytes->size() != expected)
    return "'" + chunk.string() + "' has " + std::to_string(bytes->size()) + " bytes, not " + std::to_string(expected);
  array.bytes = std::move(*bytes);
  return {};
}

}  // namespace exactgeo::store
