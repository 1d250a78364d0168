#!/usr/bin/env bash
# Issue 14: single tamp-plan runs on named instances under ONE hold of the shared build lock (the
# rounds' probes; it replaces their per-round probe scripts in docs/bench/). A line per run: the
# instance, the label, the extra arguments, the status, wall seconds, evaluations, plan cost and
# the 1-min load.
#   services/symbolic_planner/bench/probe.sh PLANNER LIMIT "EXTRA ARGS" INSTANCE...
#   INSTANCE: SET/DOMAIN/N (SET a folder of tests/data/benchmarks), e.g. pddl-more/transport/18;
#   TAMP_PROBE_LABEL: the label column (default: the planner's file name).
set -euo pipefail
[ $# -ge 4 ] || { sed -n '2,8p' "$0" >&2; exit 2; }
planner=$1 lim=$2 extra=$3
shift 3
cd "$(dirname "$0")/../../.."
label=${TAMP_PROBE_LABEL:-$(basename "$planner")}
export planner lim extra label
flock "${TAMP_BUILD_LOCK:-/tmp/tamp-build.lock}" bash -c '
for i in "$@"; do
  set=${i%%/*}; rest=${i#*/}; d=${rest%%/*}; n=${rest#*/}
  base=tests/data/benchmarks/$set/$d
  if [ -d "$base/instance-$n" ]; then dom=$base/instance-$n/domain.pddl; prob=$base/instance-$n/instance-$n.pddl
  else dom=$base/domain.pddl; prob=$base/instance-$n.pddl; fi
  s=$(date +%s.%N)
  plan=$(mktemp)
  out=$(timeout $((lim + 1)) "$planner" "$dom" "$prob" --timeout "$lim" --stats --no-check $extra 2>&1 >"$plan" | grep "; status" || true)
  e=$(date +%s.%N)
  st=$(echo "$out" | sed -nE "s/.*status ([a-z ]+);.*/\1/p"); ev=$(echo "$out" | sed -nE "s/.*evaluated ([0-9]+).*/\1/p")
  c=$(sed -nE "s/^; cost = ([0-9]+).*/\1/p" "$plan"); rm -f "$plan"
  printf "%-28s %-8s %-30s %-10s %8.2f s evals %-9s cost %-7s load %s\n" "$i" "$label" "$extra" "${st:-none}" \
    "$(echo "$e - $s" | bc)" "${ev:--}" "${c:--}" "$(cut -d" " -f1 /proc/loadavg)"
done' probe "$@"
