#!/usr/bin/env bash
# Installs what tracer needs from Debian 12's archive (as root, or prints the command), builds the
# release preset and renders the built-in Cornell box to render.png.
#   scripts/setup.sh            install + build + render
#   scripts/setup.sh --deps     install only
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  g++ clang cmake ninja-build pkg-config git ca-certificates
  libtinyobjloader-dev libfast-float-dev libstb-dev libcli11-dev libtbb-dev libhwy-dev
  libgtest-dev libgmock-dev libbenchmark-dev libembree-dev zlib1g-dev
  libclang-rt-14-dev llvm clang-format nlohmann-json3-dev libopenexr-dev
  libopenmpi-dev openmpi-bin libcpp-httplib-dev libtinygltf-dev libssl-dev
  chromium  # tracer view's browser test (headless)
)
# Node.js and npm for the browser test's playwright-core: Debian's, unless a node with npm is
# already installed (NodeSource's nodejs bundles npm and conflicts with Debian's npm package).
command -v npm >/dev/null || PACKAGES+=(nodejs npm)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  if [[ $(id -u) -eq 0 ]]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}"
  elif command -v sudo >/dev/null; then
    sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
  else
    echo "tracer setup: missing packages; run as root:" >&2
    echo "  apt-get install -y --no-install-recommends ${missing[*]}" >&2
    exit 1
  fi
fi
[[ "${1:-}" == "--deps" ]] && exit 0

cmake --preset release
cmake --build --preset release
./build/release/tracer render -o render.png --denoise --stats
echo "tracer: wrote render.png"
