#!/usr/bin/env bash
# Regenerates the suite's captures from their descriptions (perf/suite/<name>.json ->
# perf/suite/<name>/) with the path-traced reference, and measures each reference's noise floor
# (frame 0 rendered again with seed 1001, RDE printed to perf/suite/<name>.log).
#   bash perf/suite/render_suite.sh [name ...]      (from the repository root; default: all)
# Needs the built tool (build/bin/mrgi or MRGI=path). Timings: LP_NUM_THREADS=2 does not apply
# (no Vulkan); the renderer uses --threads 2.
set -euo pipefail
MRGI="${MRGI:-./build/bin/mrgi}"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then names=(desk_spot corner glass_mirror env_fisheye out_of_view moving); fi
for n in "${names[@]}"; do
  rm -rf "perf/suite/$n" "perf/suite/$n.partial"
  start=$(date +%s)
  "$MRGI" synth "perf/suite/$n.json" --out "perf/suite/$n" --threads 2 --noise-floor-seed 1001 \
    > "perf/suite/$n.log" 2> "perf/suite/$n.progress"
  end=$(date +%s)
  echo "render_seconds $((end - start))" >> "perf/suite/$n.log"
  rm -f "perf/suite/$n.progress"
  cat "perf/suite/$n.log"
done
