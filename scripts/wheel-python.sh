#!/usr/bin/env bash
# Prints the interpreter `make wheel` builds with: the oldest CPython 3.12 or later found (on PATH, or among
# pyenv's versions; the oldest, so that the wheel's test runs on the oldest Python it claims), whose wheel is the stable-ABI cp312-abi3 one that serves every CPython from 3.12 on;
# failing that python3, whose wheel is for its own version only.
set -euo pipefail
candidates=()
for v in 3.12 3.13 3.14; do candidates+=("python$v"); done
if command -v pyenv >/dev/null 2>&1; then
  root=$(pyenv root)
  for d in $(ls -d "$root"/versions/3.1[2-9]* 2>/dev/null | sort -V); do candidates+=("$d/bin/python3"); done
fi
for p in "${candidates[@]}"; do
  if exe=$("$p" -c 'import sys; assert sys.version_info >= (3, 12); print(sys.executable)' 2>/dev/null); then
    echo "$exe"
    exit 0
  fi
done
command -v python3
