#!/usr/bin/env bash
# Builds and runs the tests of a CMake preset on all cores, installing what is missing first:
#   release (default)  everything, every test (unit, validation, scenes, CLI, GL, browser, install)
#   asan               the engine's layers and their tests under Address + UndefinedBehavior sanitizers
#   tsan               the tests of threaded code (label threads) under ThreadSanitizer
#   debug              everything, unoptimised
# VRDEFORM_WERROR=ON makes warnings errors. Extra arguments go to ctest (e.g. -L validation).
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
shift || true
scripts/install-deps.sh
if [ "$preset" = release ] || [ "$preset" = debug ]; then
  scripts/install-web.sh   # three.js, playwright-core and iwer for the VR page (npm ci, once)
fi
cmake --preset "$preset"
cmake --build --preset "$preset"
ctest --preset "$preset" -j "$(nproc)" "$@"
