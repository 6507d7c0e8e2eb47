// Progress of long work on stderr: shown once the work has run for a second, only when stderr is a terminal
// and --quiet is not given; the line is rewritten in place and ended when the work is done.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace exactgeo::cli {

class Progress {
 public:
  Progress(std::string what, std::size_t total, bool quiet);
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Ends the line, if one was shown, before anything else is printed.
  void finish();
  void update(std::size_t done);

 private:
  std::string what_;
  std::size_t total_;
  bool enabled_, shown_ = false;
  std::chrono::steady_clock::time_point start_;
};

double seconds_since(std::chrono::steady_clock::time_point start);

}  // namespace exactgeo::cli
