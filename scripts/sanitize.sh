#!/usr/bin/env bash
# The sanitizer build (part of the test command, scripts/test.sh): clang with AddressSanitizer +
# UndefinedBehaviorSanitizer (a UB report aborts), -Werror, libFuzzer coverage, into
# build-asan/; then the tests again under it (tools/sanitizers: third-party leak suppressions
# only) and a short run of every fuzz target (scripts/fuzz.sh, FUZZ_SECONDS each, default 10).
# In the test command it runs the areas that read outside input (unit, capture, scene, the .oni
# reader and the fuzz corpora) to keep the command near 15 minutes on 2 cores;
# MRGI_SANITIZE_ALL=1 builds and runs every test (about 12 minutes more; last full run: 376 tests,
# no report in mrgi's code).
# To fit the CI time (the test command builds the tree twice on 2 cores): -O0 with line tables
# only, and the libraries as unity translation units (MRGI_UNITY_LIBS).
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang++ >/dev/null || { echo "sanitize.sh: clang++ not found (scripts/install-deps.sh installs it)" >&2; exit 1; }
CC=clang CXX=clang++ cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O0 -gline-tables-only" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O0 -gline-tables-only" \
  -DMRGI_SANITIZE=ON -DMRGI_WERROR=ON -DMRGI_FUZZ=ON -DMRGI_UNITY_LIBS=ON >/dev/null
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
if [ "${MRGI_SANITIZE_ALL:-0}" = 1 ]; then
  ninja -C build-asan -j"$(nproc)"
  ctest --test-dir build-asan --output-on-failure --no-tests=error -j"$(nproc)" --timeout 900
else
  ninja -C build-asan -j"$(nproc)" test_unit test_capture test_scene test_platform test_light \
    fuzz_capture_json fuzz_capture_list fuzz_tum_poses fuzz_scene_json fuzz_gltf fuzz_texture fuzz_png fuzz_hdr fuzz_oni
  # The light stage's CPU code too (environment sampling, the probeless builder and solve). Three
  # arithmetic-only tests run in the plain suite only, each about a minute at -O0 under ASan:
  # the light stage's 10,000-frame drift, the LPV propagation against the inverse square, and
  # the sphere fit's reference winding sum (the fast fit itself runs here in the other tests).
  ctest --test-dir build-asan --output-on-failure --no-tests=error -j"$(nproc)" --timeout 900 \
    -L '^(unit|capture|scene|fuzz|light)$' \
    -E 'NoDriftOverTenThousandFrames|PointSourceIrradianceAgainstTheInverseSquare|TheTreeWindingFitsWhatTheExactSumFits'
  # The .oni reader's tests too (a file that crashes the driver must be refused under ASan's
  # crash handler as well: the full run found it was not); the rest of `platform` (2.5 minutes
  # under ASan, mostly AprilTag photos) runs with MRGI_SANITIZE_ALL=1.
  ctest --test-dir build-asan --output-on-failure --no-tests=error -j"$(nproc)" --timeout 900 -R '^OpenNI'
fi
MRGI_FUZZ_BUILD=build-asan bash scripts/fuzz.sh "${FUZZ_SECONDS:-10}"
