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
# perf/suite/<name>; then perf/suite.json is synced (sync_suite_json.py). render_seconds is the
# time spent rendering the frames, summed over the runs (synth keeps it per frame in the partial;
# only a frame cut off by a kill is lost).
# Needs the built tool (build/bin/mrgi or MRGI=path). Timings: LP_NUM_THREADS=2 does not apply
# (no Vulkan); the renderer uses --threads 2.
set -euo pipefail
MRGI="${MRGI:-./build/bin/mrgi}"
STAGE=out/suite-render
names=("$@")
if [ ${#names[@]} -eq 0 ]; then names=(desk_spot corner glass_mirror env_fisheye out_of_view moving glossy_table); fi
mkdir -p "$STAGE"
for n in "${names[@]}"; do
  if [ ! -d "$STAGE/$n" ]; then
    if ! "$MRGI" synth "perf/suite/$n.json" --out "$STAGE/$n" --threads 2 --noise-floor-seed 1001 --resume \
        ${STOP_AFTER:+--stop-after "$STOP_AFTER"} > "$STAGE/$n.out" 2> "$STAGE/$n.progress"; then
      tail -n 3 "$STAGE/$n.progress" >&2
      exit 1
    fi
  fi
  if [ ! -d "$STAGE/$n" ]; then
    echo "$n: $(tail -n 1 "$STAGE/$n.progress")"
    continue
  fi
  seconds=$(sed -n 's/.*(\([0-9.]*\) s rendering over all runs).*/\1/p' "$STAGE/$n.progress" | tail -n 1)
  { grep "^reference noise floor" "$STAGE/$n.out"; printf 'render_seconds %.0f\n' "$seconds"; } > "perf/suite/$n.log"
  rm -rf "perf/suite/$n"
  mv "$STAGE/$n" "perf/suite/$n"
  rm -f "$STAGE/$n.out" "$STAGE/$n.progress"
  cat "perf/suite/$n.log"
done
python3 perf/suite/sync_suite_json.py
