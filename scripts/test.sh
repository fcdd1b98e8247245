#!/usr/bin/env bash
# Builds the CI preset (release, warnings as errors) and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
# The browser test's playwright-core (npm registry), once, as package-lock.json pins it.
if command -v npm >/dev/null && [[ ! -d tests/browser/node_modules/playwright-core ]]; then
  npm ci --prefix tests/browser --no-audit --no-fund
fi
cmake --preset ci
cmake --build --preset ci
ctest --preset ci -j2
