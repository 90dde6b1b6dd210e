#!/usr/bin/env bash
# Renders the light-estimation family (perf/suite/light/<name>.json -> perf/suite/light/<name>/)
# with the path-traced reference: about 10 s a capture on 2 cores.
#   bash perf/suite/light/render_family.sh [name ...]     (from the repository root; default: all)
# Each capture is rendered into out/light-render/<name> first and replaces perf/suite/light/<name>
# only when finished. Needs the built tool (build/bin/mrgi or MRGI=path) and ../shared/data/env
# for the HDR scenes. Regenerate the descriptions first if make_family.py changed.
set -euo pipefail
MRGI="${MRGI:-./build/bin/mrgi}"
STAGE=out/light-render
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  names=($(python3 -c 'import json; print(" ".join(s["name"] for s in json.load(open("perf/suite/light/family.json"))["scenes"]))'))
fi
mkdir -p "$STAGE"
for n in "${names[@]}"; do
  rm -rf "$STAGE/$n" "$STAGE/$n.partial"
  "$MRGI" synth "perf/suite/light/$n.json" --out "$STAGE/$n" --threads 2 2> "$STAGE/$n.progress" || {
    tail -n 3 "$STAGE/$n.progress" >&2; exit 1; }
  rm -rf "perf/suite/light/$n"
  mv "$STAGE/$n" "perf/suite/light/$n"
  echo "$n: $(tail -n 1 "$STAGE/$n.progress")"
done
