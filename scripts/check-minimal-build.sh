#!/usr/bin/env bash
# The build with every optional part left out (MRGI_WITH_*=OFF: no OpenNI2, V4L2, libcamera,
# libusb, AprilTag, Embree; no tests): configures, and compiles everything that differs from the
# full build (the input library's sources with their absent/ stand-ins, the tool's commands). The
# runtime library itself does not depend on any optional package, so the full build's compile of
# it stands for this one's. A full link: scripts/check-minimal-build.sh --full (a second compile
# of the runtime, minutes). It compiles at -O0 without debug info: it checks what compiles against
# which packages; the full build compiles the same sources at -O2 with -Werror.
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${MRGI_MINIMAL_BUILD_DIR:-build-minimal}"
mkdir -p "$dir"
cmake -S . -B "$dir" -G Ninja -DMRGI_WERROR=ON -DMRGI_BUILD_TESTS=OFF \
  -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O0 -DCMAKE_C_FLAGS_DEBUG=-O0 \
  -DMRGI_WITH_OPENNI2=OFF -DMRGI_WITH_V4L2=OFF -DMRGI_WITH_LIBCAMERA=OFF -DMRGI_WITH_LIBUSB=OFF \
  -DMRGI_WITH_APRILTAG=OFF -DMRGI_WITH_REFERENCE=OFF > "$dir/configure-minimal.log"
if [ "${1:-}" = "--full" ]; then
  cmake --build "$dir"
  "$dir/bin/mrgi" devices
  exit 0
fi
objects=$(ninja -C "$dir" -t targets all | grep -oE '^(platform/CMakeFiles/mrgi_platform_objects|examples/CMakeFiles/mrgi_tool)\.dir/[^:]*\.o' | sort -u)
ninja -C "$dir" $objects
echo "minimal build: configured and compiled $(echo "$objects" | wc -l) objects of mrgi_platform and the tool"
