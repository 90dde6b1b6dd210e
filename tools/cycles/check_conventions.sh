#!/usr/bin/env bash
# Renders each small description in tools/cycles/checks/ (64x48, one frame) with both mrgi's path
# tracer and Blender Cycles, converts the Cycles frames with `mrgi synth --from-renders`, and
# prints compare_captures.py's figures: where the two renderers should agree to within the
# Monte Carlo noise (lamp units, spot cone, bounce count, material models). About 1 minute per
# description on 2 cores. Needs blender, python3-numpy and build/bin/mrgi.
#
#   bash tools/cycles/check_conventions.sh [NAME ...]     (default: all of checks/)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${OUT:-out/cycles-checks}
mkdir -p "$out"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for f in tools/cycles/checks/*.json; do names+=("$(basename "$f" .json)"); done
fi
status=0
for n in "${names[@]}"; do
  desc=tools/cycles/checks/$n.json
  rm -rf "$out/$n.renders" "$out/$n.cycles" "$out/$n.mrgi"
  nice -n 10 blender -b --factory-startup -noaudio -P tools/cycles/render_description.py -- \
    "$desc" "$out/$n.renders" --threads 2 > "$out/$n.blender.log" 2>&1
  ./build/bin/mrgi synth "$desc" --from-renders "$out/$n.renders" --out "$out/$n.cycles" 2> /dev/null
  nice -n 10 ./build/bin/mrgi synth "$desc" --out "$out/$n.mrgi" --threads 2 > /dev/null 2>&1
  echo "== $n"
  blender -b --factory-startup -noaudio -P tools/cycles/compare_captures.py -- "$out/$n.mrgi" "$out/$n.cycles" \
    --json "$out/$n.json" 2>&1 | grep -E "^(over|checks)" || status=1
done
exit $status
