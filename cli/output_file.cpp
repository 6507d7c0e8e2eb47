// Output files that appear only when complete (OutputFile), and their removal when a signal ends the run.
#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

#include <sys/stat.h>
#include <unistd.h>

#include "outputs.hpp"

namespace exactgeo::cli {
namespace {

exactgeo::Error io_error(const std::string& message) { return exactgeo::Error(exactgeo::ErrorCode::io_error, message); }

// The temporary files of the outputs being written, for the interrupt handler to remove: slots that hold a
// path or null, so that the handler only reads atomics and calls unlink (both async-signal-safe). A command
// writes a handful of files at most; one beyond the slots is simply not cleaned up on an interrupt.
constexpr std::size_t kMaxUnfinishedOutputs = 16;
std::array<std::atomic<const char*>, kMaxUnfinishedOutputs> g_unfinished_outputs{};

void track_unfinished(const char* path) {
  for (auto& slot : g_unfinished_outputs) {
    const char* empty = nullptr;
    if (slot.compare_exchange_strong(empty, path)) return;
  }
}

void forget_unfinished(const char* path) {
  for (auto& slot : g_unfinished_outputs) {
    const char* expected = path;
    if (slot.compare_exchange_strong(expected, nullptr)) return;
  }
}

extern "C" void remove_unfinished_outputs_and_stop(int signal_number) {
  for (auto& slot : g_unfinished_outputs)
    if (const char* path = slot.load()) ::unlink(path);
  // Then end the way the signal would have: the caller sees 130 (SIGINT) or 143 (SIGTERM) from the shell.
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

}  // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  if (path_ == kStdout) {
    stream_ = stdout;
    return;
  }
  // Beside the destination, so that the rename stays on one file system; hidden, and named as unfinished.
  const std::filesystem::path destination(path_);
  temporary_ = (destination.parent_path() / ("." + destination.filename().string() + ".partial-XXXXXX")).string();
  // Tracked before it exists: mkstemp fills in the name in place, so a signal at any moment finds the file
  // it created (or none yet).
  track_unfinished(temporary_.c_str());
  const int descriptor = ::mkstemp(temporary_.data());
  if (descriptor < 0) {
    forget_unfinished(temporary_.c_str());
    throw io_error("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  // mkstemp makes the file private (0600); an output gets the permissions a new file would have.
  const ::mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(descriptor, 0666 & ~mask);
  ::close(descriptor);
}

OutputFile::~OutputFile() {
  if (path_ == kStdout) return;
  if (stream_) std::fclose(stream_);
  if (!committed_) std::remove(temporary_.c_str());
  forget_unfinished(temporary_.c_str());
}

std::FILE* OutputFile::stream() {
  if (!stream_) {
    stream_ = std::fopen(temporary_.c_str(), "wb");
    if (!stream_) throw io_error("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  return stream_;
}

void OutputFile::commit() {
  if (path_ == kStdout) {
    if (std::fflush(stdout) != 0 || std::ferror(stdout))
      throw io_error(std::string("error writing to standard output: ") + std::strerror(errno));
    committed_ = true;
    return;
  }
  if (stream_) {
    const bool failed = std::ferror(stream_) != 0;
    const bool closed = std::fclose(stream_) == 0;
    stream_ = nullptr;
    if (failed || !closed) throw io_error("error writing '" + path_ + "': " + std::strerror(errno));
  }
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0)
    throw io_error("cannot write '" + path_ + "': " + std::strerror(errno));
  committed_ = true;
}

void remove_unfinished_outputs_on_interrupt() {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal_number, remove_unfinished_outputs_and_stop);
}

void write_file(const std::string& path, const std::function<void(std::FILE*)>& write) {
  OutputFile output(path);
  write(output.stream());
  output.commit();
}

}  // namespace exactgeo::cli
