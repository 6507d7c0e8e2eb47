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

exactgeo::Error io_error(const std::string& message) { return exactgeo::Error(exactgeo::ErrorCode::io_error, message); }

exactgeo::Error invalid_argument(const std::string& message) {
  return exactgeo::Error(exactgeo::ErrorCode::invalid_argument, message);
}

namespace {

// Links followed at most, as Linux's path resolution allows (ELOOP beyond).
constexpr int kMaxLinkHops = 40;

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

OutputTarget output_target(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);  // through links
  if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_directory(status)) return {path, true};
  // Followed hop by hop rather than by canonical(), which fails on a link to a file not written yet.
  fs::path target(path);
  for (int hop = 0; hop < kMaxLinkHops && fs::is_symlink(fs::symlink_status(target, error)); ++hop) {
    const fs::path next = fs::read_symlink(target, error);
    if (error) break;
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  return {target, false};
}

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  if (path_ == kStdout) {
    stream_ = stdout;
    return;
  }
  const OutputTarget target = output_target(path_);
  if (target.special) {
    writing_ = path_;
    return;
  }
  destination_ = target.path.string();
  // Beside the destination, so that the rename stays on one file system; hidden, and named as unfinished.
  writing_ = (target.path.parent_path() / ("." + target.path.filename().string() + ".partial-XXXXXX")).string();
  // Tracked before it exists: mkstemp fills in the name in place, so a signal at any moment finds the file
  // it created (or none yet).
  track_unfinished(writing_.c_str());
  const int descriptor = ::mkstemp(writing_.data());
  if (descriptor < 0) {
    forget_unfinished(writing_.c_str());
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
  if (destination_.empty()) return;
  if (!committed_) std::remove(writing_.c_str());
  forget_unfinished(writing_.c_str());
}

std::FILE* OutputFile::stream() {
  if (!stream_) {
    stream_ = std::fopen(writing_.c_str(), "wb");
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
  if (!destination_.empty() && std::rename(writing_.c_str(), destination_.c_str()) != 0)
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
