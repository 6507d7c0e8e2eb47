// libFuzzer harness for the mesh readers. Every input is read as each format; each must return a soup whose
// indices are in range and coordinates finite, or throw exactgeo::Error. Anything else (a crash, a sanitizer
// report, a hang, another exception) is a bug. Each input is read twice, on one thread in one chunk and on
// two threads in chunks of a few bytes: the soups, or the error messages, must be the same.
// Built and run by `make test-asan` (see tests/fuzz/CMakeLists.txt).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "exactgeo/error.hpp"
#include "readers.hpp"

namespace {

void check_soup(const exactgeo::MeshSoup& soup) {
  const std::size_t vertex_count = soup.positions.size() / 3;
  if (soup.positions.size() % 3 != 0 || soup.triangles.size() % 3 != 0) std::abort();
  for (double coordinate : soup.positions) {
    if (!std::isfinite(coordinate)) std::abort();
  }
  for (std::uint32_t index : soup.triangles) {
    if (index >= vertex_count) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using Reader = exactgeo::MeshSoup (*)(const exactgeo::detail::MeshFile&, const exactgeo::detail::ParallelTeam&,
                                        std::size_t);
  static exactgeo::detail::WorkerPool one(1), two(2);
  const exactgeo::detail::MeshFile file{"fuzz", {reinterpret_cast<const char*>(data), size}};
  for (Reader reader : {&exactgeo::detail::read_obj, &exactgeo::detail::read_ply, &exactgeo::detail::read_off,
                        &exactgeo::detail::read_stl}) {
    const auto read = [&](exactgeo::detail::WorkerPool& pool, std::size_t chunk_bytes, std::string& error) {
      try {
        exactgeo::MeshSoup soup = reader(file, {pool}, chunk_bytes);
        check_soup(soup);
        return soup;
      } catch (const exactgeo::Error& e) {
        error = e.what();
        return exactgeo::MeshSoup{};
      }
    };
    std::string serial_error, chunked_error;
    const exactgeo::MeshSoup serial = read(one, exactgeo::detail::kMinChunkBytes, serial_error);
    const exactgeo::MeshSoup chunked = read(two, 1 + size % 13, chunked_error);
    if (serial_error != chunked_error || serial.positions != chunked.positions || serial.triangles != chunked.triangles)
      std::abort();
  }
  return 0;
}
