#!/usr/bin/env bash
# The main job: installs the dependencies, builds (Release), and runs a scenario end to end with
# every service as its own process on this machine. Usage: deploy/run.sh [SCENARIO] [tamp run options]
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/install_deps.sh
./deploy/build.sh release
default_scenario=config/scenarios/namo_corridor.yaml
if [ $# -gt 0 ] && [[ "$1" != -* ]]; then
  scenario="$1"; shift
  [ -f "$scenario" ] || { echo "deploy/run.sh: no scenario file $scenario" >&2; exit 30; }
  exec ./build/release/bin/tamp run "$scenario" "$@"
elif [ -f "$default_scenario" ]; then
  exec ./build/release/bin/tamp run "$default_scenario" "$@"
else
  exec ./build/release/bin/tamp run "$@"
fi
