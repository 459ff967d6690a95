#!/usr/bin/env bash
# Installs the third-party icon corpus pinned in package-lock.json into node_modules/ (npm ci,
# only when missing or stale: tests/data/npm_ci.sh). Used by tests/e2e/cli_icons_test.sh.
exec "$(dirname "$0")/../npm_ci.sh" "$(cd "$(dirname "$0")" && pwd)"
