#!/usr/bin/env bash
# The A/B performance check, locally or in CI: builds BASE_REF (a commit, branch or tag; e.g.
# the merge-base with the main branch) into its own folder, builds the working tree, and runs
# `mrgi bench --compare` of the working tree's build (the candidate) against it, interleaved
# entry by entry (perf/README.md, "A/B against the base build"). Exit 1 when the candidate is
# slower on any quantity; the report is in out/perf-compare/ (compare.md, junit.xml, ratios.png).
#   scripts/perf-check.sh BASE_REF [mrgi bench options, e.g. --compare-set full or --pairs 16]
# The base build is kept in build-perf-base/<commit>/ and reused; BASE_REF must be a commit that
# has `mrgi bench --serve` (the compare refuses one that does not, naming it).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
base_ref="$1"
shift
commit="$(git rev-parse --verify --quiet "${base_ref}^{commit}")" ||
  { echo "perf-check: '$base_ref' is not a commit of this repository" >&2; exit 2; }
base_src="build-perf-base/$commit"
if [ ! -x "$base_src/build/bin/mrgi" ]; then
  echo "perf-check: building the base $base_ref ($commit) in $base_src" >&2
  rm -rf "$base_src"
  git worktree prune
  git worktree add --detach --force "$base_src" "$commit" >/dev/null
  # perf/suite/ assets and ../shared are read by the candidate's paths; the base needs only its binary.
  cmake -S "$base_src" -B "$base_src/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  ninja -C "$base_src/build" bin/mrgi
fi
echo "perf-check: building the candidate (the working tree)" >&2
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
ninja -C build bin/mrgi
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
exec build/bin/mrgi bench --compare "$base_src/build/bin/mrgi" --out out/perf-compare "$@"
