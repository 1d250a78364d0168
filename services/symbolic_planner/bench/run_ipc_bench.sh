#!/usr/bin/env bash
# Runs the IPC benchmarks of issues 3 and 14 and writes the per-instance CSVs and summaries to
# docs/bench/. One tamp-plan process per instance, wall time and peak RSS of the child, every plan
# checked by the independent lifted plan checker. The limits are the references': 60 s for
# pddl and pddl-adl, 30 s for pddl-more. The shared build lock is taken around each planner run
# (--lock), so that builds can run between instances but never during one. The planner gets the
# limit minus 1 s as its own --timeout, so that its anytime phase (cost domains) ends with a plan
# before the driver would kill it.
# The planner runs with --stats; its statistics line (evaluations, fallbacks, ...) is the CSV's
# last column. With TAMP_BENCH_TAG=t, the files are <name>_t.csv / <name>_t_summary.md and the
# planner column says t, so that configurations can be run side by side without overwriting the
# landed results.
#   services/symbolic_planner/bench/run_ipc_bench.sh [BUILD_DIR] [SET...]
#   (default build/planner, Release; default sets: pddl pddl-adl pddl-more)
# Beside it, for the rounds of issue 14: sweep_set.sh (one set with one binary under one hold of
# the lock, a CSV per domain, extra planner arguments), probe.sh (single runs on named instances)
# and ipc_compare.py (two runs instance by instance; one run against the FF / LAMA-first
# references; coverage of several runs).
set -euo pipefail
cd "$(dirname "$0")/../../.."
build=${1:-build/planner}
shift || true
sets=("$@")
[ ${#sets[@]} -eq 0 ] && sets=(pddl pddl-adl pddl-more)
data=${TAMP_BENCHMARKS_DIR:-tests/data/benchmarks}
out=docs/bench
mkdir -p "$out"
bench="$build/bin/tamp_symbolic_planner_ipc_bench"
planner="$build/bin/tamp-plan"
for set in "${sets[@]}"; do
  case "$set" in
    pddl) name=symbolic_planner_ipc; limit=60 ;;
    pddl-adl) name=symbolic_planner_ipc_adl; limit=60 ;;
    pddl-more) name=symbolic_planner_ipc_more; limit=30 ;;
    *) name=symbolic_planner_ipc_${set//-/_}; limit=30 ;;
  esac
  label=tamp-plan
  if [ -n "${TAMP_BENCH_TAG:-}" ]; then
    name=${name}_${TAMP_BENCH_TAG}
    label=$TAMP_BENCH_TAG
  fi
  echo "== $set ($limit s), $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)" >&2
  "$bench" --planner "$planner" --set "$data/$set" --out "$out/$name.csv" --label "$label" \
    --timeout "$limit" --lock /tmp/tamp-build.lock -- --timeout "$((limit - 1))" --stats > "$out/${name}_summary.md"
  echo "== $set done, $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)" >&2
done

