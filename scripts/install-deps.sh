#!/usr/bin/env bash
# Installs the system packages a make target needs, if any is missing (Debian/Ubuntu, as root or through sudo).
# `install-deps.sh command`: what the library and the exactgeo command need (make demo, make wheel), so that a
# fresh machine gets to the demo in a minute or two; `install-deps.sh` (all): everything `make test` builds too.
set -euo pipefail
# CLI11 and nlohmann-json are header-only: the command's option parsing and its JSON summaries.
packages=(g++ cmake ninja-build libcli11-dev nlohmann-json3-dev)
if [ "${1:-all}" = all ]; then
  # The CGAL oracle, the test suite, clang with its runtime libraries (libFuzzer, the sanitizers) for the
  # sanitizer and fuzzer tests (make test-asan), and clang-format (with git-clang-format) for make lint.
  packages+=(libcgal-dev libgtest-dev libgmock-dev clang libclang-rt-14-dev clang-format)
elif [ "$1" != command ]; then
  echo "usage: $0 [command|all]" >&2
  exit 2
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "Installing: ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${missing[@]}" >/dev/null
fi
