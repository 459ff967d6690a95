#!/usr/bin/env bash
# Installs the OpenMoji corpus pinned in package-lock.json (openmoji 17.0.0, CC BY-SA 4.0: the
# artwork is fetched from npm, never committed) into node_modules/ with `npm ci` when it is
# missing or older than the lock file; prints nothing when it is up to date. Used by
# tests/e2e/cli_openmoji_test.sh. Concurrent runs wait for each other (flock on the lock file), as
# tests/data/icons/prepare.sh does.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
command -v npm >/dev/null || { echo "prepare: npm not found (scripts/setup installs npm)" >&2; exit 1; }
exec 9<package-lock.json
flock 9
if [[ ! -d node_modules || package-lock.json -nt node_modules/.package-lock.json ]]; then
  npm ci --no-audit --no-fund --loglevel=error >&2
fi
