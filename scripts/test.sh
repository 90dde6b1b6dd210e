#!/usr/bin/env bash
# The test command: installs what is needed, builds with -Werror, and runs every test (unit, capture
# and scene parsing with every refusal case, frame graph, Vulkan with validation layers on, golden
# runs against the path-traced references, reference-renderer checks, platform adapters, bench
# subset, fuzz seed corpora); then the same tests under ASan + UBSan and a short run of every fuzz
# target (scripts/sanitize.sh). SKIP_SANITIZERS=1 stops after the first pass.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# Line tables only (-g1, where the default build has full debug info): the build is most of this
# command's time on 2 cores, and backtraces, sanitizer reports and profiles still name lines.
bash scripts/build.sh -DMRGI_WERROR=ON -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
ctest --test-dir build --output-on-failure --no-tests=error -j"$(nproc)" --timeout 900
# The build with every optional package left out (configure and the parts it changes).
bash scripts/check-minimal-build.sh
# The aarch64 cross build configures against a sysroot of Debian arm64 packages (README "aarch64
# devices"; the full cross build and the qemu run are scripts/run-sample-aarch64.sh).
bash scripts/build-aarch64.sh --configure-only
# Each fuzz target for 5 s here (their seed corpora also run in CTest; `bash scripts/fuzz.sh 600`
# is the long run).
[ "${SKIP_SANITIZERS:-0}" = 1 ] || FUZZ_SECONDS="${FUZZ_SECONDS:-5}" bash scripts/sanitize.sh
