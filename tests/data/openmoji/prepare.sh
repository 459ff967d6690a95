#!/usr/bin/env bash
# Installs the OpenMoji corpus pinned in package-lock.json (openmoji 17.0.0, CC BY-SA 4.0: the
# artwork is fetched from npm, never committed) into node_modules/ (npm ci, only when missing or
# stale: tests/data/npm_ci.sh). Used by tests/e2e/cli_openmoji_test.sh.
exec "$(dirname "$0")/../npm_ci.sh" "$(cd "$(dirname "$0")" && pwd)"
