#!/usr/bin/env bash
# The main job: installs what is missing, builds (release) and runs `vrdeform run` with any
# arguments, e.g. scripts/run.sh --seconds 6 --substeps 2.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target vrdeform-cli
exec build/release/apps/vrdeform run "$@"
