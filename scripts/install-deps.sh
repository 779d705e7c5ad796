#!/usr/bin/env bash
# Installs every build and test dependency of vrdeform from Debian bookworm packages.
# Does nothing when all are present, so the run and test scripts can call it every time.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev       # small fixed-size maths
  libcli11-dev        # command-line parsing
  libfmt-dev          # formatting of reports
  libpugixml-dev zlib1g-dev   # VTK XML tet meshes
  nlohmann-json3-dev  # WEART middleware JSON messages
  liblo-dev           # OSC output for other haptic devices and tools
  libsleef-dev        # atan2 in SIMD lanes (the bending constraints)
  libtomlplusplus-dev # scene files
  tetgen              # optional mesher, run as a separate program (AGPL)
  libgtest-dev libgmock-dev googletest   # unit tests
  libbenchmark-dev    # benchmarks
  libbullet-dev       # Bullet soft bodies: only for bench/bullet_compare (not a test)
  clang-format        # code style check
  clang libclang-rt-14-dev lld   # libFuzzer for the fuzz targets (fuzz/); lld drops their unused code
  libboost1.81-dev    # Boost.Beast (HTTP, WebSocket) for the VR server (vrdeform serve)
  libssl-dev          # OpenSSL: serve --tls (HTTPS, WSS, its self-signed certificate)
  chromium            # the VR page's browser test (headless, with an emulated headset)
  libepoxy-dev libegl-dev libegl1 libegl-mesa0 libgl1-mesa-dri   # OpenGL renderer; headless on Mesa's EGL surfaceless
  libglfw3-dev libimgui-dev libstb-dev   # desktop viewer window and panels; PNG frames
  librsvg2-dev        # the study report's figures as PNG beside their SVG
  xvfb xauth          # the viewer's test under a virtual X server
  ffmpeg              # MP4 from headless frames (vrdeform render; optional at run time)
  python3-dev pybind11-dev python3-numpy python3-pytest   # the Python module (python/) and its tests
  python3-matplotlib python3-nbconvert python3-ipykernel   # the Python examples: plots, the notebook run in the tests
)

command -v node >/dev/null || packages+=(nodejs npm)  # the VR page's npm packages and browser test

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to apt-get install ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
