// Memory for the mesh's and the engine's arrays (surface_mesh.hpp): small ones from the heap, large ones
// mapped on their own and, on Linux, advised into transparent huge pages.
#include <cstdint>
#include <cstdlib>
#include <new>

#include "surface_mesh.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace exactgeo::detail {
namespace {

#if defined(__linux__)
constexpr std::size_t kHugePage = std::size_t{2} << 20;
// From this size on an array gets its own mapping: below it, the heap reuses memory that is already mapped.
constexpr std::size_t kMappedBytes = 2 * kHugePage;

constexpr std::size_t kPage = 4096;

// The first multiple of `page` at or after `value`.
std::uintptr_t round_up(std::uintptr_t value, std::size_t page) { return (value + page - 1) / page * page; }

// The mapping is the array's size in whole small pages, from a huge-page boundary: every huge page wholly
// inside it can be a huge page, and the tail stays in small ones. (Rounding the size up to huge pages
// backed up to 2 MB per array that nothing used: 9 MB of a 400K-face run's 132 MB peak.)
std::size_t mapped_size(std::size_t bytes) { return round_up(bytes, kPage); }

// madvise(advice) on the pages of `page` bytes wholly inside [p, p + bytes): the advice covers whole pages,
// and the ones at the ends may hold other allocations. Advice is a hint: failing is fine.
void advise_whole_pages(const void* p, std::size_t bytes, std::size_t page, int advice) noexcept {
  const auto address = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t first = round_up(address, page), last = (address + bytes) / page * page;
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, advice);
}
#endif

}  // namespace

void advise_huge_pages(const void* p, std::size_t bytes) noexcept {
#if defined(__linux__)
  if (bytes >= kMappedBytes) advise_whole_pages(p, bytes, kHugePage, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

void populate_for_writing(void* p, std::size_t bytes) noexcept {
#if defined(__linux__)
#if defined(MADV_POPULATE_WRITE)
  constexpr int kPopulateWrite = MADV_POPULATE_WRITE;
#else
  constexpr int kPopulateWrite = 23;  // Linux's value, for C libraries older than the call (wheels' glibc 2.17)
#endif
  advise_whole_pages(p, bytes, kPage, kPopulateWrite);
#else
  (void)p;
  (void)bytes;
#endif
}

void* allocate_mesh_bytes(std::size_t bytes, std::size_t alignment) {
#if defined(__linux__)
  if (bytes >= kMappedBytes) {
    // Mapped one huge page larger than needed, then trimmed to start on a huge-page boundary.
    const std::size_t size = mapped_size(bytes);
    void* mapped = mmap(nullptr, size + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED) throw std::bad_alloc();
    const auto address = reinterpret_cast<std::uintptr_t>(mapped);
    const std::uintptr_t aligned = round_up(address, kHugePage);
    if (aligned > address) munmap(mapped, aligned - address);
    const std::uintptr_t tail = aligned + size, mapped_end = address + size + kHugePage;
    if (mapped_end > tail) munmap(reinterpret_cast<void*>(tail), mapped_end - tail);
    madvise(reinterpret_cast<void*>(aligned), size, MADV_HUGEPAGE);  // a hint: without it, small pages
    return reinterpret_cast<void*>(aligned);
  }
#endif
  return ::operator new(bytes, std::align_val_t{alignment});
}

void free_mesh_bytes(void* p, std::size_t bytes, std::size_t alignment) noexcept {
  if (p == nullptr) return;
#if defined(__linux__)
  if (bytes >= kMappedBytes) {
    munmap(p, mapped_size(bytes));
    return;
  }
#endif
  ::operator delete(p, std::align_val_t{alignment});
}

}  // namespace exactgeo::detail
