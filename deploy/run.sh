#!/usr/bin/env bash
# The main job: installs the dependencies, builds (Release), and runs a scenario end to end with
# every service as its own process on this machine.
# Usage: deploy/run.sh [SCENARIO] [tamp run options]
# The simulated robot runs at config/services/sim.yaml's pace (4x real time) unless a
# --realtime-factor is given (1 = real time); executed and predicted times are simulated seconds
# either way.
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/install_deps.sh
./deploy/build.sh release
default_scenario=config/scenarios/namo_corridor.yaml
scenario=()
if [ $# -gt 0 ] && [[ "$1" != -* ]]; then
  [ -f "$1" ] || { echo "deploy/run.sh: no scenario file $1" >&2; exit 30; }
  scenario=("$1"); shift
elif [ -f "$default_scenario" ]; then
  scenario=("$default_scenario")
fi
exec ./build/release/bin/tamp run "${scenario[@]}" "$@"
