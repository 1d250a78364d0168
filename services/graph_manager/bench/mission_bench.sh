#!/usr/bin/env bash
# Mission benchmark (issue 11): every scenario given (default: every shipped scenario) under both
# policies, one `tamp run` each with seed 1, a fresh effort-estimator store per run, the simulator
# at REALTIME_FACTOR x real time. Since issue 12 this is the evaluation runner
# (tools/evaluation/evaluate.py, which also takes NAMO worlds and folders, more policies and seeds)
# with this benchmark's settings; it writes OUT.csv, OUT.md and the plot (default
# docs/bench/mission_bench.*) and exits non-zero when it ran nothing.
#   services/graph_manager/bench/mission_bench.sh [BUILD_DIR] [SCENARIO.yaml ...]
set -euo pipefail
cd "$(dirname "$0")/../../.."
build=${1:-build/release}; shift || true
scenarios=("$@")
if [ ${#scenarios[@]} -eq 0 ]; then scenarios=(config/scenarios); fi
exec tools/evaluation/evaluate.py --build "$build" --policies effort,infeasible --seeds 1 \
  --realtime-factor "${REALTIME_FACTOR:-3}" --out "${OUT:-docs/bench/mission_bench}" "${scenarios[@]}"
