#!/usr/bin/env bash
# The main job: installs what is needed, builds, and replays the bundled sample capture
# (data/sample, capture format v1 with path-traced references) through the `baseline` technique
# on lavapipe with 2 threads. Writes out/frames/*.png, out/stats.json, out/summary.json and
# out/side_by_side.png (camera | mrgi | reference).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
./build/bin/mrgi replay data/sample --technique "${MRGI_TECHNIQUE:-baseline}" --out out "$@"
echo "wrote $(pwd)/out (frames/, stats.json, summary.json, side_by_side.png)"
