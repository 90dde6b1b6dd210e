#!/usr/bin/env bash
# Cross-builds the mrgi library and tool for aarch64 Linux into build-aarch64/ (one command):
# assembles the sysroot from Debian's arm64 packages (scripts/make-aarch64-sysroot.sh, reused
# when present), configures with `cmake --preset aarch64` and builds.
#   --configure-only   stop after configuring (what CI checks: seconds, not minutes)
# Extra arguments go to cmake (-DMRGI_WITH_...). MRGI_SYSROOT picks another sysroot.
set -euo pipefail
cd "$(dirname "$0")/.."
configure_only=0
if [ "${1:-}" = "--configure-only" ]; then
  configure_only=1
  shift
fi
if [ -z "${MRGI_SYSROOT:-}" ]; then
  bash scripts/make-aarch64-sysroot.sh
fi
mkdir -p build-aarch64
cmake --preset aarch64 "$@" > build-aarch64/configure.log 2>&1 || {
  cat build-aarch64/configure.log
  echo "build-aarch64: configure failed (log above)" >&2
  exit 1
}
grep -E "^-- mrgi:" build-aarch64/configure.log || true
if [ "$configure_only" = 1 ]; then
  echo "build-aarch64: configured build-aarch64/ for $(grep -m1 CMAKE_SYSTEM_PROCESSOR build-aarch64/CMakeCache.txt 2>/dev/null || echo aarch64)"
  exit 0
fi
cmake --build build-aarch64 --target mrgi_tool -j"$(nproc)"
file build-aarch64/bin/mrgi | cut -d, -f1-2
