#!/usr/bin/env bash
# Runs the IPC benchmark of issue 3 and writes the per-instance CSVs and summaries to docs/bench/.
# One tamp-plan process per instance, 60 s limit, wall time and peak RSS of the child, every plan
# checked by the independent lifted plan checker. Takes the shared build lock for the whole run.
#   services/symbolic_planner/bench/run_ipc_bench.sh [BUILD_DIR]   (default build/planner, Release)
set -euo pipefail
cd "$(dirname "$0")/../../.."
build=${1:-build/planner}
data=${TAMP_BENCHMARKS_DIR:-tests/data/benchmarks}
out=docs/bench
mkdir -p "$out"
bench="$build/bin/tamp_symbolic_planner_ipc_bench"
planner="$build/bin/tamp-plan"
flock /tmp/tamp-build.lock "$bench" --planner "$planner" --set "$data/pddl" \
  --out "$out/symbolic_planner_ipc.csv" --timeout 60 > "$out/symbolic_planner_ipc_summary.md"
flock /tmp/tamp-build.lock "$bench" --planner "$planner" --set "$data/pddl-adl" \
  --out "$out/symbolic_planner_ipc_adl.csv" --timeout 60 > "$out/symbolic_planner_ipc_adl_summary.md"
cat "$out/symbolic_planner_ipc_summary.md" "$out/symbolic_planner_ipc_adl_summary.md"
