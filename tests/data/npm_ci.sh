#!/usr/bin/env bash
# Usage: tests/data/npm_ci.sh DIR. Installs the npm packages pinned in DIR/package-lock.json
# (`npm ci`) into DIR/node_modules when it is missing or older than the lock file; prints nothing
# when it is up to date. Concurrent runs wait for each other (flock on the lock file), as
# client/web/scripts/prepare.sh does. The corpora's prepare.sh scripts call it.
set -euo pipefail
cd "$1"
command -v npm >/dev/null || { echo "prepare: npm not found (scripts/setup installs npm)" >&2; exit 1; }
exec 9<package-lock.json
flock 9
if [[ ! -d node_modules || package-lock.json -nt node_modules/.package-lock.json ]]; then
  npm ci --no-audit --no-fund --loglevel=error >&2
fi
