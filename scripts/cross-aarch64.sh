#!/usr/bin/env bash
# Builds the solver's layers (core, mesh, sim) and their tests (core, validation) for aarch64 with
# Debian's cross toolchain and runs the tests under qemu-user: the portable 4-lane path (NEON), no
# x86 flags, public headers without intrinsics. Installs the toolchain, qemu and the arm64
# packages (multiarch) when missing. Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
packages=(g++-aarch64-linux-gnu qemu-user libfmt-dev:arm64 libgtest-dev:arm64)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "cross-aarch64: installing ${missing[*]}"
  dpkg --print-foreign-architectures | grep -qx arm64 || $sudo dpkg --add-architecture arm64
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
cmake -S . -B build/aarch64 -G Ninja -DCMAKE_BUILD_TYPE=Release -DVRDEFORM_SOLVER_ONLY=ON \
  -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/aarch64-linux-gnu.cmake -DVRDEFORM_WERROR="${VRDEFORM_WERROR:-OFF}"
cmake --build build/aarch64
ctest --test-dir build/aarch64 --output-on-failure -j "$(nproc)" "$@"
