#!/usr/bin/env bash
# Issue 14: one benchmark set swept with one planner binary under ONE hold of the shared build lock
# (the rounds' sweeps since the twenty-eighth; it replaces their per-round sweep scripts in
# docs/bench/): one driver call per domain, the planner's --timeout one second below the driver's,
# --stats, every plan checked by the driver. Writes OUT/LABEL_DOMAIN.{csv,md,err}; a line per domain
# with the time and load on stderr.
#   services/symbolic_planner/bench/sweep_set.sh SET LIMIT LABEL PLANNER BENCH OUT [PLANNER_ARGS...]
#   SET: a folder of tests/data/benchmarks (pddl, pddl-more, pddl-adl) or a path to a set folder;
#   LIMIT: seconds per instance (the references': 60 for pddl and pddl-adl, 30 for pddl-more);
#   PLANNER / BENCH: tamp-plan and tamp_symbolic_planner_ipc_bench (copies, so that a build during
#   the sweep does not change them); TAMP_BENCH_DOMAINS="a b": only those domains.
set -euo pipefail
[ $# -ge 6 ] || { sed -n '2,12p' "$0" >&2; exit 2; }
set_arg=$1 limit=$2 label=$3 planner=$4 bench=$5 out=$6
shift 6
root=$(cd "$(dirname "$0")/../../.." && pwd)
dir=$set_arg
[ -d "$dir" ] || dir=$root/tests/data/benchmarks/$set_arg
domains=${TAMP_BENCH_DOMAINS:-$(cd "$dir" && for d in */; do echo "${d%/}"; done)}
mkdir -p "$out"
lock=${TAMP_BUILD_LOCK:-/tmp/tamp-build.lock}
export dir limit label planner bench out
flock "$lock" bash -c '
for d in '"$(echo $domains)"'; do
  echo "== $label $d start $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)" >&2
  "$bench" --planner "$planner" --set "$dir" --domain "$d" --out "$out/${label}_$d.csv" --label "$label" \
    --timeout "$limit" -- --timeout $((limit - 1)) --stats "$@" > "$out/${label}_$d.md" 2> "$out/${label}_$d.err" || true
  echo "== $label $d end $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)" >&2
done' sweep "$@"
