#!/usr/bin/env bash
# Installs the system packages the build and the tests need, if any is missing (Debian/Ubuntu, as root).
set -euo pipefail
# clang and its runtime libraries (libFuzzer, the sanitizers) build the sanitizer and fuzzer tests (make test-asan).
packages=(g++ cmake ninja-build libcgal-dev libgtest-dev libgmock-dev libcli11-dev nlohmann-json3-dev
          clang libclang-rt-14-dev)
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
