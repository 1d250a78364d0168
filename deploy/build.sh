#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release). Usage: deploy/build.sh [preset] [ninja targets...]
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
shift || true
export CCACHE_BASEDIR="$PWD"
export CCACHE_NOHASHDIR=1
# Keep a fresh configure from inheriting a developer's partial-area setting.
cmake --preset "$preset" -DTAMP_ONLY_AREAS= > "build-$preset.configure.log" 2>&1 || { cat "build-$preset.configure.log"; exit 1; }
rm -f "build-$preset.configure.log"
if [ $# -gt 0 ]; then
  cmake --build --preset "$preset" --target "$@"
else
  cmake --build --preset "$preset"
fi
