#!/usr/bin/env bash
# Makes client/web runnable: installs the npm packages from package-lock.json (`npm ci`) when
# node_modules is missing or older than the lock file, then generates the protobuf code and
# builds the page into dist/. Used by scripts/web and tests/e2e/web_test.sh.
set -euo pipefail
web=$(cd "$(dirname "$0")/.." && pwd)
cd "$web"
command -v node >/dev/null || { echo "prepare: node not found (scripts/setup installs nodejs)" >&2; exit 1; }
command -v npm >/dev/null || { echo "prepare: npm not found (scripts/setup installs npm)" >&2; exit 1; }
command -v protoc >/dev/null || { echo "prepare: protoc not found (scripts/setup installs protobuf-compiler)" >&2; exit 1; }
if [[ ! -d node_modules || package-lock.json -nt node_modules/.package-lock.json ]]; then
  npm ci --no-audit --no-fund --loglevel=error
fi
node scripts/gen.mjs >/dev/null
node scripts/build-page.mjs >/dev/null
