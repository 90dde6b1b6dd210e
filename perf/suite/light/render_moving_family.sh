#!/usr/bin/env bash
# Renders the moving-camera light family (perf/suite/light/moving/<name>.json ->
# perf/suite/light/moving/<name>/) with mrgi synth, then joins each light-switch pair
# (splice_switch.py). About 50 s a sweep and 3 s a switch half on 2 cores; 10 minutes in all.
#   bash perf/suite/light/render_moving_family.sh [name ...]    (from the repository root; default all)
# The renders are not committed (15 MB): the descriptions and seeds fix them, and mrgi synth
# renders the same images on any machine. Each capture is rendered into out/light-render/ first
# and replaces its folder only when finished. Needs the built tool (build/bin/mrgi or MRGI=path)
# and ../shared/data/env for the HDR scenes.
set -euo pipefail
MRGI="${MRGI:-./build/bin/mrgi}"
DIR=perf/suite/light/moving
STAGE=out/light-render
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  names=($(python3 -c 'import json; m=json.load(open("'$DIR'/family.json"))
print(" ".join([s["name"] for s in m["scenes"]] + [w["name"][:-len("_switch")] + h for w in m["switches"] for h in ("_off", "_on")]))'))
fi
mkdir -p "$STAGE"
for n in "${names[@]}"; do
  rm -rf "$STAGE/$n"
  "$MRGI" synth "$DIR/$n.json" --out "$STAGE/$n" --threads 2 2> "$STAGE/$n.progress" || {
    tail -n 3 "$STAGE/$n.progress" >&2; exit 1; }
  rm -rf "$DIR/$n"
  mv "$STAGE/$n" "$DIR/$n"
  echo "$n: $(tail -n 1 "$STAGE/$n.progress")"
done
python3 perf/suite/light/splice_switch.py "$DIR/family.json"
