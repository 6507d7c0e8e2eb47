#!/usr/bin/env bash
# Prints one interpreter per CPython version from 3.9 on that this machine has (on PATH as python3.X, or among
# pyenv's versions), oldest first: what `make wheels` builds and tests wheels for.
set -euo pipefail
declare -A seen
candidates=()
for minor in $(seq 9 20); do candidates+=("python3.$minor"); done
if command -v pyenv >/dev/null 2>&1; then
  for d in $(ls -d "$(pyenv root)"/versions/3.* 2>/dev/null | sort -V); do candidates+=("$d/bin/python3"); done
fi
for p in "${candidates[@]}"; do
  describe='import sys; assert sys.version_info >= (3, 9); print("%d.%d" % sys.version_info[:2], sys.executable)'
  found=$("$p" -c "$describe" 2>/dev/null) || continue
  version=${found%% *}
  [ -n "${seen[$version]:-}" ] || { seen[$version]=1; echo "$version ${found#* }"; }
done | sort -V | cut -d' ' -f2 | paste -sd' '
