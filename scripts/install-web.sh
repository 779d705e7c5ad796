#!/usr/bin/env bash
# Installs the VR page's npm packages (three.js; playwright-core and iwer for its browser test)
# into web/node_modules from the committed web/package-lock.json. Does nothing when they are
# there and match the lock file, so the test script can call it every time.
set -euo pipefail
cd "$(dirname "$0")/../web"
command -v npm >/dev/null || { echo "install-web: npm is missing (scripts/install-deps.sh installs it)" >&2; exit 1; }
# npm writes node_modules/.package-lock.json on every install: newer than the lock file means done.
if [ -f node_modules/.package-lock.json ] && [ node_modules/.package-lock.json -nt package-lock.json ]; then
  exit 0
fi
echo "install-web: npm ci in web/"
npm ci --no-audit --no-fund --loglevel=error
