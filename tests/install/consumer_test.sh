#!/bin/bash
# Installs the build into a fresh prefix and builds examples/frames_from_memory on its own against
# it, twice: with find_package(mrgi) (CMake) and with `pkg-config mrgi` (a plain compiler line);
# runs both. Fails on any step. Usage: consumer_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/mrgi-install-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" > "$work/install.log"
# Only the public API is installed: no internal header, no third-party header of mrgi's own.
test -f "$prefix/include/mrgi/runtime.h"
test -f "$prefix/include/mrgi/version.h"
test -f "$prefix/include/mrgi/platform/capture.h"
if [ -e "$prefix/include/mrgi/json_reader.h" ]; then echo "internal header installed: json_reader.h"; exit 1; fi
# Vulkan's headers only in the opt-in interop header (mrgi/vulkan_device.h: an app that owns a
# Vulkan device has them), never through the core API.
if grep -rlE '#include <(nlohmann|vulkan|Eigen|tiny_gltf|embree)' "$prefix/include" | grep -v '/mrgi/vulkan_device.h$'; then
  echo "a public header includes a third-party header other than GLM (Vulkan: mrgi/vulkan_device.h only)"; exit 1
fi
if grep -rlE '#include [<"]mrgi/vulkan_device.h' "$prefix/include/mrgi"; then
  echo "a core public header includes mrgi/vulkan_device.h (the core API must not need Vulkan's headers)"; exit 1
fi
test -x "$prefix/bin/mrgi"
"$prefix/bin/mrgi" --version
# The installed library: a versioned SONAME, no debug info (split into lib/debug/), small.
lib=$(readlink -f "$prefix/lib/libmrgi.so")
version=$(sed -n 's/^project(mrgi VERSION \([0-9]*\)\.\([0-9]*\)\..*/\1.\2/p' "$src/CMakeLists.txt")
readelf -d "$lib" | grep -F "Library soname: [libmrgi.so.$version]" > /dev/null || {
  echo "libmrgi.so has no versioned SONAME libmrgi.so.$version:"; readelf -d "$lib" | grep SONAME; exit 1; }
if readelf -S "$lib" | grep -F .debug_info > /dev/null; then echo "installed $lib carries debug info"; exit 1; fi
test -s "$prefix/lib/debug/$(basename "$lib").debug"
size=$(stat -c %s "$lib")
if [ "$size" -ge $((15 * 1024 * 1024)) ]; then echo "installed $lib is $size bytes (limit 15 MiB)"; exit 1; fi
# What the installed libraries export: the public API only (exported_symbols_test.sh).
bash "$src/tests/install/exported_symbols_test.sh" "$lib" "$prefix"/include/mrgi/*.h -- mrgi::create_runtime
bash "$src/tests/install/exported_symbols_test.sh" "$(readlink -f "$prefix/lib/libmrgi_platform.so")" \
  "$prefix/include/mrgi/platform" -- mrgi::open_source
# The installed tool (mrgi linked in statically) needs nothing from the build tree.
if ldd "$prefix/bin/mrgi" | grep -F "$build/"; then echo "installed tool links the build tree"; exit 1; fi

sample=$src/data/sample/virtual/0_bunny.glb
# CMake consumer, outside the source tree.
cp -r "$src/examples/frames_from_memory" "$work/consumer"
cmake -S "$work/consumer" -B "$work/consumer-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release > "$work/configure.log"
cmake --build "$work/consumer-build" -j2 > "$work/build.log"
"$work/consumer-build/frames_from_memory" "$sample" "$work/cmake.ppm"
# An app on its own Vulkan device (mrgi/vulkan_device.h, the platform library's capture reader),
# built against the prefix like any app.
cp -r "$src/examples/app_device" "$work/app_device"
cmake -S "$work/app_device" -B "$work/app_device-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release > "$work/app_device-configure.log"
cmake --build "$work/app_device-build" -j2 > "$work/app_device-build.log"
"$work/app_device-build/app_device" "$src/data/sample" 2 | grep -q "the app's device still works after the runtime"
# pkg-config consumer.
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
test "$(pkg-config --modversion mrgi)" = "$(sed -n 's/^project(mrgi VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")"
c++ -std=c++20 -O1 "$work/consumer/main.cpp" -o "$work/pc_consumer" $(pkg-config --cflags --libs mrgi)
"$work/pc_consumer" "$sample" "$work/pc.ppm"
cmp "$work/cmake.ppm" "$work/pc.ppm"
echo "consumers built and ran against $prefix (CMake and pkg-config; an app's own Vulkan device)"
