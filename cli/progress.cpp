#include "progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <utility>

namespace exactgeo::cli {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Progress::Progress(std::string what, std::size_t total, bool quiet)
    : what_(std::move(what)), total_(total), enabled_(!quiet && ::isatty(::fileno(stderr))),
      start_(std::chrono::steady_clock::now()) {}

void Progress::finish() {
  if (shown_) std::fputc('\n', stderr);
  shown_ = false;
  enabled_ = false;
}

void Progress::update(std::size_t done) {
  if (!enabled_ || seconds_since(start_) < 1.0) return;
  std::fprintf(stderr, "\rexactgeo: %s %zu/%zu (%.0f%%)", what_.c_str(), done, total_,
               total_ ? 100.0 * double(done) / double(total_) : 100.0);
  std::fflush(stderr);
  shown_ = true;
}

}  // namespace exactgeo::cli
