#!/usr/bin/env bash
# Regenerates the suite's captures from their descriptions (perf/suite/<name>.json ->
# perf/suite/<name>/) with the path-traced reference, and measures each reference's noise floor
# (frame 0 rendered again with seed 1001, RDE printed to perf/suite/<name>.log).
#   bash perf/suite/render_suite.sh [name ...]      (from the repository root; default: all)
#   STOP_AFTER=2 bash perf/suite/render_suite.sh corner   (at most 2 frames per scene this run)
# Renders are resumable: each goes to out/suite-render/<name> first; a run that is killed or
# stopped by STOP_AFTER keeps its finished frames in out/suite-render/<name>.partial and running
# the script again goes on from there (`mrgi synth --resume`, which refuses a partial made from
# another description, input files or settings). Only a finished capture replaces
# perf/suite/<name>; then perf/suite.json is synced (sync_suite_json.py). render_seconds sums the
# runs that ended normally (a killed run's time is not counted).
# Needs the built tool (build/bin/mrgi or MRGI=path). Timings: LP_NUM_THREADS=2 does not apply
# (no Vulkan); the renderer uses --threads 2.
set -euo pipefail
MRGI="${MRGI:-./build/bin/mrgi}"
STAGE=out/suite-render
names=("$@")
if [ ${#names[@]} -eq 0 ]; then names=(desk_spot corner glass_mirror env_fisheye out_of_view moving); fi
mkdir -p "$STAGE"
for n in "${names[@]}"; do
  if [ ! -d "$STAGE/$n" ]; then
    start=$(date +%s)
    "$MRGI" synth "perf/suite/$n.json" --out "$STAGE/$n" --threads 2 --noise-floor-seed 1001 --resume \
      ${STOP_AFTER:+--stop-after "$STOP_AFTER"} > "$STAGE/$n.out" 2> "$STAGE/$n.progress"
    before=$(cat "$STAGE/$n.seconds" 2>/dev/null || echo 0)
    echo $((before + $(date +%s) - start)) > "$STAGE/$n.seconds"
  fi
  if [ ! -d "$STAGE/$n" ]; then
    echo "$n: $(tail -n 1 "$STAGE/$n.progress")"
    continue
  fi
  { grep "^reference noise floor" "$STAGE/$n.out"; echo "render_seconds $(cat "$STAGE/$n.seconds")"; } \
    > "perf/suite/$n.log"
  rm -rf "perf/suite/$n"
  mv "$STAGE/$n" "perf/suite/$n"
  rm -f "$STAGE/$n.out" "$STAGE/$n.progress" "$STAGE/$n.seconds"
  cat "perf/suite/$n.log"
done
python3 perf/suite/sync_suite_json.py
