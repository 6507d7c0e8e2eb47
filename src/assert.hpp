// EXACTGEO_ASSERT(condition): a check of one of the engine's invariants, compiled in where the CMake option
// EXACTGEO_ASSERTIONS defines the macro of that name (on by default in Debug and sanitizer builds, so in
// `make test-asan`) and compiled out otherwise: the condition is then not even evaluated, and Release builds
// pay nothing.
//
// A broken invariant throws Error(ErrorCode::internal) rather than aborting: a test then fails with the
// message and the others still run, the command line exits with its internal-error code (3), and Python
// raises instead of losing the interpreter. The engine resets all its state at the start of each run, so
// a solver that threw is still usable.
#pragma once

#include <string>

#include "exactgeo/error.hpp"

namespace exactgeo::detail {

[[noreturn, gnu::cold, gnu::noinline]] inline void invariant_broken(const char* file, int line,
                                                                     const char* condition) {
  throw Error(ErrorCode::internal,
              std::string(file) + ":" + std::to_string(line) + ": invariant broken: " + condition);
}

}  // namespace exactgeo::detail

#ifdef EXACTGEO_ASSERTIONS
#define EXACTGEO_ASSERT(condition) \
  ((condition) ? static_cast<void>(0) : ::exactgeo::detail::invariant_broken(__FILE__, __LINE__, #condition))
#else
#define EXACTGEO_ASSERT(condition) static_cast<void>(0)
#endif
