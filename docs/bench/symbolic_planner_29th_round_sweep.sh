#!/bin/bash
# Issue 14, twenty-ninth round (as run; /tmp/r29 held the binaries copied from build/ci: tamp-plan-main
# = main 1d9cf7e's tamp-plan, tamp-plan-<commit> = this branch's, and the driver).
# sweep.sh SET LIMIT TAG "BIN1 BIN2" DOMAIN... : one driver call per domain and binary, in turn
cd /work/planner-r29
set=$1; limit=$2; tag=$3; bins=$4; shift 4
for d in "$@"; do
  for b in $bins; do
    echo "== $set $d $b start $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
    /tmp/r29/tamp_symbolic_planner_ipc_bench --planner /tmp/r29/tamp-plan-$b --set tests/data/benchmarks/$set --domain $d \
      --out /tmp/r29/${tag}_${b}_${d}.csv --label $b --timeout $limit --lock /tmp/tamp-build.lock -- --timeout $((limit-1)) --stats > /tmp/r29/${tag}_${b}_${d}.md 2>/tmp/r29/${tag}_${b}_${d}.err
    echo "== $set $d $b end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
  done
done
