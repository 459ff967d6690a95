#!/usr/bin/env bash
# Makes client/web runnable: installs the npm packages from package-lock.json (`npm ci`) when
# node_modules is missing or older than the lock file, then generates the protobuf code and
# builds the page into dist/. Used by scripts/web and tests/e2e/web_test.sh.
# --deps: only the npm packages (tests/e2e/lottie_web_test.sh, which must not rebuild dist/
# under a running web_test). Concurrent runs wait for each other's `npm ci` (flock on the lock file).
set -euo pipefail
deps_only=0
[[ "${1:-}" == "--deps" ]] && deps_only=1
web=$(cd "$(dirname "$0")/.." && pwd)
cd "$web"
command -v node >/dev/null || { echo "prepare: node not found (scripts/setup installs nodejs)" >&2; exit 1; }
# package.json's engines (npm ci would only warn): Debian 12's nodejs 18 is the oldest supported.
node -e 'process.exit(Number(process.versions.node.split(".")[0]) >= 18 ? 0 : 1)' ||
  { echo "prepare: Node.js >= 18 needed, found $(node --version)" >&2; exit 1; }
command -v npm >/dev/null || { echo "prepare: npm not found (scripts/setup installs npm)" >&2; exit 1; }
((deps_only)) || command -v protoc >/dev/null ||
  { echo "prepare: protoc not found (scripts/setup installs protobuf-compiler)" >&2; exit 1; }
exec 9<package-lock.json
flock 9
if [[ ! -d node_modules || package-lock.json -nt node_modules/.package-lock.json ]]; then
  npm ci --no-audit --no-fund --loglevel=error
fi
((deps_only)) && exit 0
node scripts/gen.mjs >/dev/null
node scripts/build-page.mjs >/dev/null
