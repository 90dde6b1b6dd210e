#!/usr/bin/env bash
# Renders the moving-camera light family (perf/suite/light/moving/<name>.json ->
# perf/suite/light/moving/<name>/) with render_family.sh, then joins each light-switch pair
# (splice_switch.py). About 50 s a sweep and 3 s a switch half on 2 cores; 10 minutes in all.
#   bash perf/suite/light/render_moving_family.sh [name ...]    (from the repository root; default
#                                                                every sweep and switch half)
# The renders are not committed (28 MB): the descriptions and seeds fix them, and mrgi synth
# renders the same images on any machine. Needs the built tool (build/bin/mrgi or MRGI=path) and
# ../shared/data/env for the HDR scenes.
set -euo pipefail
DIR=perf/suite/light/moving
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  names=($(python3 -c 'import json, sys; m = json.load(open(sys.argv[1]))
print(" ".join([s["name"] for s in m["scenes"]] + [w["name"][:-len("_switch")] + h for w in m["switches"] for h in ("_off", "_on")]))' "$DIR/family.json"))
fi
FAMILY_DIR="$DIR" bash perf/suite/light/render_family.sh "${names[@]}"
python3 perf/suite/light/splice_switch.py "$DIR/family.json"
