#!/usr/bin/env bash
# Checks that the C++ lines changed since BASE are formatted as .clang-format says, and prints what clang-format
# would make of them if they are not (then fails).
#
#   scripts/check-format.sh [BASE]
#
# BASE is a commit; by default the point where this branch left main (origin/main, or main), so on main itself
# only uncommitted changes count and a clean tree has nothing to check. The changed lines are those of the
# working tree (committed since BASE, staged or not; new files once added to git). Only those lines are checked,
# not the rest of their files: the tree was written before the style file, and formatting whole files would
# turn every small change into a large one. `git clang-format BASE` formats them in place.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "check-format: not a git checkout, nothing to compare"
  exit 0
fi
if ! command -v git-clang-format >/dev/null; then
  echo "check-format: git-clang-format not found (Debian/Ubuntu: apt-get install clang-format)" >&2
  exit 2
fi

base=${1:-}
if [ -z "$base" ]; then
  for main in origin/main main; do
    if git rev-parse -q --verify "$main^{commit}" >/dev/null; then
      base=$(git merge-base HEAD "$main")
      break
    fi
  done
  base=${base:-HEAD}
fi
git rev-parse -q --verify "$base^{commit}" >/dev/null || { echo "check-format: $base is not a commit" >&2; exit 2; }

# git-clang-format exits 0 whether or not it would change something (up to LLVM 14 at least), so its output
# says: one of these two lines when the changed lines are formatted, a diff of the changes otherwise.
output=$(git clang-format --binary clang-format --extensions c,cc,cpp,h,hpp --diff "$base" --)
case "$output" in
  "no modified files to format" | "clang-format did not modify any files")
    echo "check-format: the C++ lines changed since $(git rev-parse --short "$base") are formatted"
    ;;
  *)
    echo "$output"
    echo "check-format: the lines above, changed since $(git rev-parse --short "$base"), are not formatted as" \
         ".clang-format says; 'git clang-format $base' formats them" >&2
    exit 1
    ;;
esac
