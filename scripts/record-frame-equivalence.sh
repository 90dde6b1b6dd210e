#!/usr/bin/env bash
# Re-records the frame-equivalence test's frames and RDE tables (tests/data/frame_equivalence/:
# every technique at every level on every suite scene, RDE against each capture's reference)
# from the current build, for the scenes and techniques given (default: all), and shows what
# changed. Run it when a change is meant to change what a user sees, and commit the records with
# the change, saying why: the test command fails on any frame or RDE that differs from them
# (1/255 on 99.9 % of the pixels, RDE within 0.002; the test command checks every level on
# desk_spot and the two cheapest elsewhere, `MRGI_FRAME_EQUIVALENCE_LEVELS=all ctest --test-dir
# build -R FrameEquivalence` every level everywhere).
#   scripts/record-frame-equivalence.sh [SCENE|all] [TECHNIQUE|all]
# e.g. scripts/record-frame-equivalence.sh env_fisheye dvct
set -euo pipefail
cd "$(dirname "$0")/.."
scene="${1:-all}" technique="${2:-all}"
test_bin=build/tests/test_equivalence
[ -x "$test_bin" ] || { echo "record-frame-equivalence: $test_bin not built (bash scripts/build.sh)" >&2; exit 2; }
filter="Suite/FrameEquivalence.MatchesTheRecordedFrames/"
case "$scene/$technique" in
  all/all) filter="${filter}*" ;;
  all/*) filter="${filter}*_${technique}" ;;
  */all) filter="${filter}${scene}_*" ;;
  *) filter="${filter}${scene}_${technique}" ;;
esac
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
MRGI_RECORD_FRAME_EQUIVALENCE="$out" "$test_bin" --gtest_filter="$filter" --gtest_brief=1
recorded=0
for dir in "$out"/*/; do
  s="$(basename "$dir")"
  mkdir -p "tests/data/frame_equivalence/$s"
  # The stored frame (frame 2) of each level and the RDE table; the other frames stay out.
  for f in "$dir"*.f2.delta.png "$dir"*.rde.tsv; do
    [ -e "$f" ] || continue
    cp "$f" "tests/data/frame_equivalence/$s/"
    recorded=$((recorded + 1))
  done
done
echo "record-frame-equivalence: $recorded files written under tests/data/frame_equivalence/; changed:"
git status --short -- tests/data/frame_equivalence | sed 's/^/  /'
git diff --no-color -U0 -- 'tests/data/frame_equivalence/*.rde.tsv' | grep -E '^[-+][0-9]' | sed 's/^/  /' || true
