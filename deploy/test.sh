#!/usr/bin/env bash
# Installs the dependencies, builds everything with warnings as errors, and runs every test
# (unit, contract, multi-process integration). This is what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/install_deps.sh
./deploy/build.sh ci
ctest --preset ci -j "$(nproc)" --timeout 600
