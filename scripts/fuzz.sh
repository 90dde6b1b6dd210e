#!/usr/bin/env bash
# Runs every fuzz target (tools/fuzz) under libFuzzer with ASan + UBSan for SECONDS each
# (default 60; the documented long run is 600), starting from the committed seed corpus (and the
# Kinect recording of ../shared for the .oni target, when present). Builds with clang into
# $MRGI_FUZZ_BUILD (default build-asan, the sanitizer build of scripts/sanitize.sh, configured
# the same way). New corpus entries go to BUILD/corpus/<target>/ (never into the repository); a
# crash leaves its input as BUILD/crash-<target>-* and makes this script exit 1.
#   bash scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
case "$seconds" in ''|*[!0-9]*) echo "fuzz.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2;; esac
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (scripts/install-deps.sh installs it)" >&2; exit 1; }
B="${MRGI_FUZZ_BUILD:-build-asan}"
CC=clang CXX=clang++ cmake -S . -B "$B" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O0 -gline-tables-only" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O0 -gline-tables-only" \
  -DMRGI_SANITIZE=ON -DMRGI_WERROR=ON -DMRGI_FUZZ=ON -DMRGI_UNITY_LIBS=ON >/dev/null
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(capture_json capture_list tum_poses scene_json gltf texture png hdr oni)
ninja -C "$B" -j"$(nproc)" "${targets[@]/#/fuzz_}"
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
failed=()
for t in "${targets[@]}"; do
  corpus="$B/corpus/$t"
  mkdir -p "$corpus"
  # A file argument would make libFuzzer run just that file: extra seeds go into the run corpus.
  [ "$t" = oni ] && [ -f ../shared/data/openni/kinect-12frames.oni ] && cp -n ../shared/data/openni/kinect-12frames.oni "$corpus/"
  echo "fuzz.sh: $t for ${seconds}s"
  # -rss_limit_mb: the parsers' own caps hold memory far below this (2 GiB covers the ASan
  # shadow); -timeout: an input taking 10 s is a hang, a finding.
  if ! "$B"/fuzz/fuzz_"$t" "$corpus" tools/fuzz/corpus/"$t" -max_total_time="$seconds" -timeout=10 \
       -rss_limit_mb=2048 -max_len=262144 -print_final_stats=1 -artifact_prefix="$B/crash-$t-" \
       > "$B/fuzz-$t.log" 2>&1; then
    failed+=("$t")
    tail -40 "$B/fuzz-$t.log" >&2
  fi
  grep -E "^stat::number_of_executed_units|^#[0-9]+ *DONE" "$B/fuzz-$t.log" | tail -2 || true
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: findings in ${failed[*]} (inputs: $B/crash-*; logs: $B/fuzz-*.log)" >&2
  exit 1
fi
echo "fuzz.sh: ${#targets[@]} targets, ${seconds}s each, no findings"
