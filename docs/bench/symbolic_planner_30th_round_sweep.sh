#!/bin/bash
# Issue 14, thirtieth round (as run; /tmp/r30 holds the binaries copied from build/ci: tamp-plan-<tag>
# and the driver). sweep.sh SET LIMIT TAG BIN DOMAIN... : one driver call per domain, the lock per
# instance (the driver's --lock), the planner's --timeout one second below the driver's.
cd /work/planner-r30
set=$1; limit=$2; tag=$3; b=$4; shift 4
for d in "$@"; do
  echo "== $set $d $b start $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
  /tmp/r30/tamp_symbolic_planner_ipc_bench --planner /tmp/r30/tamp-plan-$b --set tests/data/benchmarks/$set --domain $d \
    --out /tmp/r30/out/${tag}_${b}_${d}.csv --label $b --timeout $limit --lock /tmp/tamp-build.lock -- --timeout $((limit-1)) --stats \
    > /tmp/r30/out/${tag}_${b}_${d}.md 2>/tmp/r30/out/${tag}_${b}_${d}.err
  echo "== $set $d $b end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
done
# --- from 05:02 UTC: sweep2.sh, the lock per domain ---
#!/bin/bash
# Issue 14, thirtieth round (as run; /tmp/r30 holds the binaries copied from build/ci: tamp-plan-<tag>
# and the driver). sweep2.sh SET LIMIT TAG BIN DOMAIN... : one driver call per domain, the whole call
# under one hold of the lock (the other engineer's mission runs took the lock between instances,
# about 30 s a wait), the planner's --timeout one second below the driver's.
cd /work/planner-r30
set=$1; limit=$2; tag=$3; b=$4; shift 4
for d in "$@"; do
  flock /tmp/tamp-build.lock bash -c "
  echo \"== $set $d $b start \$(date -u +%T) load \$(cut -d' ' -f1-3 /proc/loadavg)\"
  /tmp/r30/tamp_symbolic_planner_ipc_bench --planner /tmp/r30/tamp-plan-$b --set tests/data/benchmarks/$set --domain $d \
    --out /tmp/r30/out/${tag}_${b}_${d}.csv --label $b --timeout $limit -- --timeout $((limit-1)) --stats \
    > /tmp/r30/out/${tag}_${b}_${d}.md 2>/tmp/r30/out/${tag}_${b}_${d}.err
  echo \"== $set $d $b end \$(date -u +%T) load \$(cut -d' ' -f1-3 /proc/loadavg)\""
done
# --- from 05:32 UTC: sweep3.sh, one hold of the lock per list of domains ---
#!/bin/bash
# Issue 14, thirtieth round (as run from 05:32 UTC): sweep3.sh SET LIMIT TAG BIN DOMAIN... : one hold
# of the lock for all the domains given (one sweep), one driver call per domain inside it.
cd /work/planner-r30
set=$1; limit=$2; tag=$3; b=$4; shift 4
flock /tmp/tamp-build.lock bash -c '
set=$1; limit=$2; tag=$3; b=$4; shift 4
for d in "$@"; do
  echo "== $set $d $b start $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"
  /tmp/r30/tamp_symbolic_planner_ipc_bench --planner /tmp/r30/tamp-plan-$b --set tests/data/benchmarks/$set --domain $d \
    --out /tmp/r30/out/${tag}_${b}_${d}.csv --label $b --timeout $limit -- --timeout $((limit-1)) --stats \
    > /tmp/r30/out/${tag}_${b}_${d}.md 2>/tmp/r30/out/${tag}_${b}_${d}.err
  echo "== $set $d $b end $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"
done' sweep "$set" "$limit" "$tag" "$b" "$@"

# --- from 06:01 UTC: sweep4.sh (lazy_beside_both on) ---
#!/bin/bash
# Issue 14, thirtieth round (as run from 06:01 UTC): sweep4.sh, sweep3.sh with --lazy-beside-both true; SET LIMIT TAG BIN DOMAIN... : one hold
# of the lock for all the domains given (one sweep), one driver call per domain inside it.
cd /work/planner-r30
set=$1; limit=$2; tag=$3; b=$4; shift 4
flock /tmp/tamp-build.lock bash -c '
set=$1; limit=$2; tag=$3; b=$4; shift 4
for d in "$@"; do
  echo "== $set $d $b start $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"
  /tmp/r30/tamp_symbolic_planner_ipc_bench --planner /tmp/r30/tamp-plan-$b --set tests/data/benchmarks/$set --domain $d \
    --out /tmp/r30/out/${tag}_${b}_${d}.csv --label $b --timeout $limit -- --timeout $((limit-1)) --stats --lazy-beside-both true \
    > /tmp/r30/out/${tag}_${b}_${d}.md 2>/tmp/r30/out/${tag}_${b}_${d}.err
  echo "== $set $d $b end $(date -u +%T) load $(cut -d" " -f1-3 /proc/loadavg)"
done' sweep "$set" "$limit" "$tag" "$b" "$@"
