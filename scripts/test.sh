#!/usr/bin/env bash
# Builds and runs every test: installs what is missing, configures the preset (default: release;
# also debug, asan, tsan). VRDEFORM_WERROR=ON makes warnings errors., builds everything and runs CTest on both cores.
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
scripts/install-deps.sh
scripts/install-web.sh   # three.js, playwright-core and iwer for the VR page (npm ci, once)
cmake --preset "$preset"
cmake --build --preset "$preset"
ctest --preset "$preset" -j "$(nproc)"
