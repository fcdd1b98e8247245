#!/usr/bin/env bash
# Builds the CI preset (release, warnings as errors) and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset ci
cmake --build --preset ci
ctest --preset ci -j2
