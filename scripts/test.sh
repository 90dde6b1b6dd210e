#!/usr/bin/env bash
# The test command: installs what is needed, builds, and runs every test (unit, capture and scene
# parsing with every refusal case, frame graph, Vulkan with validation layers on, golden runs
# against the path-traced references, reference-renderer checks, platform adapters, bench subset).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
ctest --test-dir build --output-on-failure --no-tests=error -j"$(nproc)" --timeout 900
