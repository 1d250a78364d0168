#!/bin/bash
# Issue 14, thirty-first round (as run): sweep.sh SET LIMIT TAG BIN [EXTRA] : one hold of the lock for
# the whole set, one driver call per domain inside it, the planner's --timeout one second below the driver's.
cd /work/planner31
set=$1; limit=$2; tag=$3; b=$4; extra=${5:-}
doms=$(cd tests/data/benchmarks/$set && for d in */; do echo ${d%/}; done)
flock /tmp/tamp-build.lock bash -c '
set=$1; limit=$2; tag=$3; b=$4; extra=$5; shift 5
for d in "$@"; do
  echo "== $set $d $b start $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"
  /tmp/p31/tamp_symbolic_planner_ipc_bench --planner /tmp/p31/tamp-plan-$b --set tests/data/benchmarks/$set --domain $d \
    --out /tmp/p31/out/${tag}_${b}_${d}.csv --label $b --timeout $limit -- --timeout $((limit-1)) --stats $extra \
    > /tmp/p31/out/${tag}_${b}_${d}.md 2>/tmp/p31/out/${tag}_${b}_${d}.err
  echo "== $set $d $b end $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"
done' sweep "$set" "$limit" "$tag" "$b" "$extra" $doms
