#!/usr/bin/env bash
# Builds everything and runs every test on all cores: installs what is missing, configures the
# preset (default: release; also debug, asan, tsan). VRDEFORM_WERROR=ON makes warnings errors.
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
scripts/install-deps.sh
scripts/install-web.sh   # three.js, playwright-core and iwer for the VR page (npm ci, once)
cmake --preset "$preset"
cmake --build --preset "$preset"
ctest --preset "$preset" -j "$(nproc)"
