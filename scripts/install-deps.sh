#!/usr/bin/env bash
# System packages for building and testing softshadow on Debian 12: the Vulkan loader, Mesa's
# lavapipe (a CPU Vulkan driver), the Khronos validation layers, and the shader compiler
# (libshaderc-dev with the glslang and SPIRV-Tools archives it links against); DejaVu Sans for
# the plots of `softshadow bench`; valgrind, which tests/c_abi.rs runs the C bad-calls program under;
# twm and xprop (x11-utils), with which tests/window.rs iconifies its window under Xvfb; the Xlib
# and xcb headers (libx11-dev, libxcb1-dev) for the C program that opens its own window there.
set -euo pipefail
packages=(mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-validationlayers
          libshaderc-dev glslang-dev spirv-tools pkg-config fonts-dejavu-core
          libx11-6 libx11-dev libxcb1-dev libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0 xvfb
          valgrind twm x11-utils)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
