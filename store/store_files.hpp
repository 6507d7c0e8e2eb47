// The files of a Zarr format 3 store as the matrix store writes them: every file and folder appears whole
// (written or built beside its place, synced, renamed into it), and every array is uncompressed (codecs: bytes,
// little-endian), so that its chunks are the bytes both writers hash and both verifiers read back.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "exactgeo/error.hpp"

namespace exactgeo::store {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

inline constexpr int kZarrFormat = 3;

// The store's own errors: a file that cannot be written, and a store that is not what the request needs.
exactgeo::Error io_error(const std::string& message);
exactgeo::Error invalid_store(const std::string& message);

// A hidden name beside `final` for building it: the process and a random number keep racing processes apart.
fs::path temporary_beside(const fs::path& final);

// What build_folder_into_place does with a folder already at `final`.
enum class Existing {
  kept,      // left as it is (another process's store, made first)
  replaced,  // moved aside and removed: leftover pieces are never trusted
};

// Builds a folder at a hidden name beside `final`, then renames it into place, so that it appears whole.
// rename(2) replaces an empty folder and fails on a full one: a folder there first is kept (the one built is
// removed, and the result is false) or replaced, as `existing` says. Nothing is left behind if building fails
// or an interrupt (SIGINT, SIGTERM, SIGHUP) arrives meanwhile: they are held back while the folder is built
// and renamed, and one that arrived is let in once the folder is removed.
bool build_folder_into_place(const fs::path& final, Existing existing,
                             const std::function<void(const fs::path&)>& build);

// The file appears whole or not at all, and its bytes are on disk before it does: a marker renamed into place
// after it cannot outlive it in a crash.
void write_whole(const fs::path& path, std::span<const unsigned char> bytes);
void write_json_whole(const fs::path& path, const Json& json);

// A Zarr group's metadata, and a group at `folder` with these attributes.
Json group_metadata(const Json& attributes);
void write_group(const fs::path& folder, const Json& attributes = Json::object());

// The metadata of a Zarr v3 array stored uncompressed (codecs: bytes, little-endian), as zarr-python 3 writes it.
Json array_metadata(std::span<const std::size_t> shape, std::span<const std::size_t> chunk_shape,
                    std::string_view data_type, const Json& fill_value,
                    const std::vector<std::string>& dimension_names);

// A small array stored as one chunk (the whole array; chunk key c/0, c/0/0, ...).
void write_array(const fs::path& folder, std::span<const std::size_t> shape, std::string_view data_type,
                 const Json& fill_value, const std::vector<std::string>& dimension_names,
                 std::span<const unsigned char> bytes);

// The JSON object in `path`, or nothing if there is no such file; throws invalid_store naming the file if it
// holds anything else (a file cut short or overwritten).
std::optional<Json> read_json(const fs::path& path);
// Reads the JSON object in `path` into `json`; returns why it cannot (naming the file), or nothing.
std::string read_json_into(const fs::path& path, Json& json);
// The bytes of a whole file, or nothing if it cannot be read.
std::optional<std::vector<unsigned char>> read_file(const fs::path& path);

// Why the array whose metadata is `metadata` (read from `metadata_path`) does not store its chunks as `expected`
// says (its shape, data type, chunks, chunk keys and fill value, uncompressed); empty if it does.
std::string array_problem(const fs::path& metadata_path, const Json& metadata, const Json& expected);

// An array stored whole in one chunk, as write_array writes it.
struct WholeArray {
  std::vector<std::size_t> shape;
  std::vector<unsigned char> bytes;  // little-endian
};
// Reads the array in `folder` whose data type is `data_type` and whose shape has `rank` sizes, whatever they are,
// into `array`; returns why it cannot be read as write_array would have written an array of that shape (naming
// the file), or nothing. Zarr leaves out a chunk holding the fill value alone (0): an absent chunk reads as zeros.
std::string read_whole_array(const fs::path& folder, std::string_view data_type, std::size_t rank, WholeArray& array);

}  // namespace exactgeo::store
