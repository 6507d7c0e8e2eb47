// libFuzzer harness for the mesh readers. Every input is read as each format; each must return a soup whose
// indices are in range and coordinates finite, or throw exactgeo::Error. Anything else (a crash, a sanitizer
// report, a hang, another exception) is a bug.
// Built and run by `make test-asan` (see tests/fuzz/CMakeLists.txt).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

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
  using Reader = exactgeo::MeshSoup (*)(const exactgeo::detail::MeshFile&);
  const exactgeo::detail::MeshFile file{"fuzz", {reinterpret_cast<const char*>(data), size}};
  for (Reader reader : {&exactgeo::detail::read_obj, &exactgeo::detail::read_ply, &exactgeo::detail::read_off,
                        &exactgeo::detail::read_stl}) {
    try {
      check_soup(reader(file));
    } catch (const exactgeo::Error&) {
    }
  }
  return 0;
}
