#!/usr/bin/env bash
# The main job: installs what is missing, builds (release) and runs `vrdeform run`: by default the
# liver scene headless with its scripted poke and grasp, writing its outputs to out/liver. Arguments
# replace the default, e.g. scripts/run.sh jelly --seconds 4 --out out/jelly.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target vrdeform-cli
if [ $# -eq 0 ]; then set -- liver --out out/liver; fi
exec build/release/apps/vrdeform run "$@"
