#!/bin/bash
# Issue 14, thirty-first round (as run): blocks' nine solved instances, three rounds of driver calls per binary
# (main, n32), alternating, under one hold of the lock; one driver call per instance (--problem).
cd /work/planner31
flock /tmp/tamp-build.lock bash -c '
echo "start $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"
for r in 1 2 3; do for b in main n32; do for n in 5 10 15 20 25 30 35 45 60; do
  /tmp/p31/tamp_symbolic_planner_ipc_bench --planner /tmp/p31/tamp-plan-$b --set tests/data/benchmarks/pddl --domain blocks \
    --problem instance-$n --out /tmp/p31/out/blk_${b}_r${r}_$n.csv --label $b --timeout 60 -- --timeout 59 --stats > /dev/null 2>&1
done; done; done
echo "end $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"'
