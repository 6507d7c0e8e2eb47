// Long work called from Python: run without the GIL on a worker thread, stopped by Ctrl-C (or by an
// exception from a progress callback) within milliseconds, with progress passed to Python as it goes. Short
// work runs on the calling thread, where a worker's overhead would show.
#pragma once

#include <nanobind/nanobind.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <future>
#include <optional>
#include <stop_token>
#include <thread>
#include <utility>

#include "exactgeo/exactgeo.hpp"

namespace nb = nanobind;

namespace exactgeo::python {

// Progress of long work as the worker reports it: units done out of a total (rows, samples, vertices).
struct ProgressCounter {
  std::atomic<std::size_t> done{0};
  std::atomic<std::size_t> total{0};
};

// Runs `work(stop, progress)` on a worker thread. This thread waits without the GIL, taking it every 50 ms to
// let Python handle signals and to pass the progress to `on_progress(done, total)` (None: nobody listens).
// Ctrl-C stops the work (GeodesicOptions::stop ends it within milliseconds) and raises KeyboardInterrupt once
// the worker has returned; an exception from `on_progress` stops it the same way.
template <class Work>
auto run_interruptibly(const nb::object& on_progress, Work&& work) {
  using Result = decltype(work(std::stop_token{}, std::declval<ProgressCounter&>()));
  std::stop_source stop;
  ProgressCounter progress;
  std::optional<Result> result;
  std::exception_ptr failure;
  bool python_raised = false;
  {
    nb::gil_scoped_release release;
    std::promise<void> finished;
    std::future<void> done = finished.get_future();
    std::jthread worker([&] {
      try {
        result.emplace(work(stop.get_token(), progress));
      } catch (...) {
        failure = std::current_exception();
      }
      finished.set_value();
    });
    std::size_t reported = 0;
    while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      nb::gil_scoped_acquire acquire;
      bool raised = PyErr_CheckSignals() != 0;
      const std::size_t now = progress.done.load();
      if (!raised && !on_progress.is_none() && now != reported) {
        reported = now;
        try {
          on_progress(now, progress.total.load());
        } catch (nb::python_error& e) {
          e.restore();
          raised = true;
        }
      }
      if (raised) {
        python_raised = true;
        stop.request_stop();
        break;
      }
    }
  }  // the worker is joined here, without the GIL
  if (python_raised) throw nb::python_error();
  if (failure) std::rethrow_exception(failure);
  return std::move(*result);
}

// Meshes this large take long enough to build (tens of milliseconds and more) to be worth a worker thread
// that Ctrl-C can stop; smaller ones are built on the calling thread (without the GIL).
constexpr std::size_t kInterruptibleFaces = 40000;
// About the bytes a face takes in a mesh file (an OBJ's `f` line and half a `v` line).
constexpr std::uintmax_t kFileBytesPerFace = 40;

// A mesh built by `build(options)`: on a worker thread that Ctrl-C stops (with progress in thousandths of
// the build) when it is large or progress is asked for, else here.
template <class Build>
Mesh build_mesh(const nb::object& progress, std::size_t faces, MeshOptions options, Build&& build) {
  if (progress.is_none() && faces < kInterruptibleFaces) {
    nb::gil_scoped_release release;
    return build(options);
  }
  return run_interruptibly(progress, [&](std::stop_token stop, ProgressCounter& counter) {
    counter.total = 1000;
    options.stop = stop;
    options.progress = [&](double fraction) { counter.done = static_cast<std::size_t>(1000 * fraction); };
    return build(options);
  });
}

}  // namespace exactgeo::python
