#!/usr/bin/env bash
# Runs the aarch64 build of the tool under qemu-user on the bundled sample (lavapipe from the
# sysroot, LP_NUM_THREADS=2) and compares its frames with the native build's, pixel by pixel.
# Builds either when missing (scripts/build-aarch64.sh, scripts/build.sh). Writes
# out/aarch64/ (the qemu run) and out/native/ (the native one); exits 1 if a frame differs.
# Extra arguments go to both replays (default: --technique baseline --level high; a fixed level:
# under --level auto each build would choose by its own speed, and qemu is slower).
set -euo pipefail
cd "$(dirname "$0")/.."
SYSROOT="${MRGI_SYSROOT:-$PWD/build-aarch64-sysroot}"
[ -x build-aarch64/bin/mrgi ] || bash scripts/build-aarch64.sh
[ -x build/bin/mrgi ] || bash scripts/build.sh
command -v qemu-aarch64-static > /dev/null || { echo "qemu-aarch64-static not found: apt-get install qemu-user-static" >&2; exit 1; }
export LP_NUM_THREADS="${LP_NUM_THREADS:-2}"
args=("$@")
[ ${#args[@]} -gt 0 ] || args=(--technique baseline --level high)
icd="$SYSROOT/usr/share/vulkan/icd.d/lvp_icd.aarch64.json"
echo "run-sample-aarch64: native replay"
./build/bin/mrgi replay data/sample "${args[@]}" --out out/native -q > /dev/null
echo "run-sample-aarch64: aarch64 replay under qemu-user (lavapipe, emulated: minutes)"
start=$(date +%s)
# -L: the emulated program's absolute paths (its loader, libraries, the ICD's driver) resolve in
# the sysroot first.
VK_ICD_FILENAMES="$icd" qemu-aarch64-static -L "$SYSROOT" build-aarch64/bin/mrgi replay data/sample "${args[@]}" \
  --out out/aarch64 -q > /dev/null
echo "run-sample-aarch64: qemu run took $(( $(date +%s) - start )) s"
n=0; differ=0
for f in out/native/frames/*.png; do
  n=$((n + 1))
  cmp -s "$f" "out/aarch64/frames/$(basename "$f")" || { differ=$((differ + 1)); echo "differs: $(basename "$f")"; }
done
[ "$n" -gt 0 ] || { echo "run-sample-aarch64: no frames" >&2; exit 1; }
if [ "$differ" -gt 0 ]; then
  echo "run-sample-aarch64: $differ of $n frames differ between the aarch64 and the native build" >&2
  exit 1
fi
echo "run-sample-aarch64: all $n frames identical (byte for byte) to the native build's"
