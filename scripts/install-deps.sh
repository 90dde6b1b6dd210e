#!/usr/bin/env bash
# Installs every Debian package mrgi's build, tools and tests need (Debian 12).
# Idempotent: packages already present are skipped by apt. Needs root (or sudo).
set -euo pipefail
PKGS=(
  build-essential cmake ninja-build pkg-config git doxygen
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools libspirv-cross-c-shared-dev
  libglm-dev libeigen3-dev libmeshoptimizer-dev libtinygltf-dev nlohmann-json3-dev libstb-dev libtinyexr-dev libopenexr-dev
  libcli11-dev libembree-dev libgtest-dev libgmock-dev libbenchmark-dev
  libapriltag-dev libv4l-dev libcamera-dev libopenni2-dev libusb-1.0-0-dev
  libpng-dev zlib1g-dev libjpeg62-turbo-dev
  libglfw3-dev libx11-dev libxrandr-dev xvfb xdotool
  clang libclang-rt-14-dev
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PKGS[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
