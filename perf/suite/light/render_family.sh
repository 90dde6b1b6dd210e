#!/usr/bin/env bash
# Renders a light-estimation family (DIR/<name>.json -> DIR/<name>/, DIR = FAMILY_DIR or
# perf/suite/light) with the path-traced reference: about 10 s a still capture on 2 cores.
#   bash perf/suite/light/render_family.sh [name ...]     (from the repository root; default: every
#                                                          scene of DIR/family.json)
# Each capture is rendered into out/light-render/<name> first and replaces DIR/<name> only when
# finished. Needs the built tool (build/bin/mrgi or MRGI=path) and ../shared/data/env for the HDR
# scenes. Regenerate the descriptions first if make_family.py changed.
set -euo pipefail
MRGI="${MRGI:-./build/bin/mrgi}"
DIR="${FAMILY_DIR:-perf/suite/light}"
STAGE=out/light-render
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  names=($(python3 -c 'import json, sys; print(" ".join(s["name"] for s in json.load(open(sys.argv[1]))["scenes"]))' "$DIR/family.json"))
fi
mkdir -p "$STAGE"
for n in "${names[@]}"; do
  rm -rf "$STAGE/$n" "$STAGE/$n.partial"
  "$MRGI" synth "$DIR/$n.json" --out "$STAGE/$n" --threads 2 2> "$STAGE/$n.progress" || {
    tail -n 3 "$STAGE/$n.progress" >&2; exit 1; }
  rm -rf "$DIR/$n"
  mv "$STAGE/$n" "$DIR/$n"
  echo "$n: $(tail -n 1 "$STAGE/$n.progress")"
done
