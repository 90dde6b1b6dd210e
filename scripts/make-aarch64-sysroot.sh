#!/usr/bin/env bash
# Assembles an aarch64 (arm64) sysroot for cross-building mrgi from Debian 12 packages, with
# `dpkg -x` into a folder: no `dpkg --add-architecture arm64` on the build host (on Debian 12 the
# multiarch route makes apt remove the amd64 libopenexr-dev the native build needs).
#
# Usage: scripts/make-aarch64-sysroot.sh [SYSROOT]       (default: build-aarch64-sysroot/)
# Then:  MRGI_SYSROOT=$PWD/build-aarch64-sysroot cmake --preset aarch64 && cmake --build build-aarch64
#
# What it does:
#  1. installs the host's cross compiler and qemu-user (Debian packages g++-aarch64-linux-gnu,
#     qemu-user-static) when missing;
#  2. runs a private apt (its own state, cache and lists under SYSROOT.apt/, the host's sources,
#     architecture arm64, an empty dpkg status) to download the runtime's -dev packages, the
#     Vulkan loader and lavapipe with everything they depend on;
#  3. extracts each .deb with dpkg -x, merges /lib into /usr/lib as Debian 12 systems do, and
#     turns absolute symbolic links into links inside the sysroot.
# Idempotent: downloaded packages are kept in SYSROOT.apt/ and a finished sysroot is reused
# (delete it to rebuild). Needs root (or sudo) only for step 1.
set -euo pipefail
cd "$(dirname "$0")/.."
SYSROOT="$(realpath -m "${1:-build-aarch64-sysroot}")"
APTDIR="${SYSROOT}.apt"

# The runtime's and the tool's needs (cmake/MrgiDependencies.cmake), arm64 builds of them, plus
# what the qemu run of the tool needs (Vulkan loader, lavapipe). The adapters and the path tracer
# are optional and left out: their packages are not in the sysroot, so AUTO turns them off.
PKGS=(
  libc6-dev libstdc++-12-dev
  libvulkan-dev mesa-vulkan-drivers
  libglm-dev libeigen3-dev libmeshoptimizer-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libtinyexr-dev libopenexr-dev libcli11-dev libspirv-cross-c-shared-dev
  libpng-dev zlib1g-dev libjpeg62-turbo-dev
)
HOST_PKGS=(g++-aarch64-linux-gnu qemu-user-static glslang-tools)

if [ -f "$SYSROOT/.mrgi-sysroot-complete" ]; then
  echo "make-aarch64-sysroot: $SYSROOT is complete (delete it to rebuild)"
  exit 0
fi

missing=()
for p in "${HOST_PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "make-aarch64-sysroot: installing host packages ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

mkdir -p "$APTDIR"/{lists/partial,cache/archives/partial,etc/sources.list.d,etc/preferences.d}
: > "$APTDIR/status"
# The host's own package sources (deb822 or one-line), read by the private apt for arm64.
cp /etc/apt/sources.list.d/*.sources "$APTDIR/etc/sources.list.d/" 2>/dev/null || true
cp /etc/apt/sources.list "$APTDIR/etc/sources.list" 2>/dev/null || : > "$APTDIR/etc/sources.list"
APT_OPTS=(
  -o "APT::Architecture=arm64" -o "APT::Architectures::=arm64"
  -o "Dir::State=$APTDIR" -o "Dir::State::Lists=$APTDIR/lists" -o "Dir::State::status=$APTDIR/status"
  -o "Dir::Cache=$APTDIR/cache" -o "Dir::Etc::SourceList=$APTDIR/etc/sources.list"
  -o "Dir::Etc::SourceParts=$APTDIR/etc/sources.list.d" -o "Dir::Etc::Preferences=$APTDIR/etc/preferences"
  -o "Dir::Etc::PreferencesParts=$APTDIR/etc/preferences.d"
  -o "APT::Install-Recommends=false" -o "Debug::NoLocking=true"
)
echo "make-aarch64-sysroot: reading the arm64 package lists"
apt-get "${APT_OPTS[@]}" update -qq
echo "make-aarch64-sysroot: downloading ${PKGS[*]} and their dependencies (arm64)"
apt-get "${APT_OPTS[@]}" install -y -qq --download-only "${PKGS[@]}" >/dev/null

rm -rf "$SYSROOT.partial"
mkdir -p "$SYSROOT.partial"
n=0
for deb in "$APTDIR"/cache/archives/*.deb; do
  dpkg -x "$deb" "$SYSROOT.partial"
  n=$((n + 1))
done
cd "$SYSROOT.partial"
# Debian 12 systems have /lib, /bin and /sbin merged into /usr; packages still ship both.
for d in lib bin sbin; do
  if [ -d "$d" ] && [ ! -L "$d" ]; then
    mkdir -p "usr/$d"
    cp -a "$d"/. "usr/$d"/
    rm -rf "$d"
  fi
  ln -sfn "usr/$d" "$d"
done
# An absolute link (/usr/lib/aarch64-linux-gnu/libfoo.so -> /lib/...) would point into the host.
find . -type l -lname '/*' | while read -r link; do
  target="$(readlink "$link")"
  rel="$(realpath -m --relative-to="$(dirname "$link")" ".${target}")"
  ln -sfn "$rel" "$link"
done
cd - >/dev/null
rm -rf "$SYSROOT"
mv "$SYSROOT.partial" "$SYSROOT"
date -u +%FT%TZ > "$SYSROOT/.mrgi-sysroot-complete"
echo "make-aarch64-sysroot: $n packages extracted into $SYSROOT ($(du -sh "$SYSROOT" | cut -f1))"
