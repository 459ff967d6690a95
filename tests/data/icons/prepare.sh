#!/usr/bin/env bash
# Installs the third-party icon corpus pinned in package-lock.json (`npm ci`) into node_modules/
# when it is missing or older than the lock file; prints nothing when it is up to date. Used by
# tests/e2e/cli_icons_test.sh. Concurrent runs wait for each other (flock on the lock file), as
# client/web/scripts/prepare.sh does.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
command -v npm >/dev/null || { echo "prepare: npm not found (scripts/setup installs npm)" >&2; exit 1; }
exec 9<package-lock.json
flock 9
if [[ ! -d node_modules || package-lock.json -nt node_modules/.package-lock.json ]]; then
  npm ci --no-audit --no-fund --loglevel=error >&2
fi
