#!/bin/bash
# ab.sh REPS DOMAIN PROBLEM BIN... : per round (2), each binary as perf stat -r REPS (task-clock ms, elapsed s), under the lock
reps=$1; dom=$2; prob=$3; shift 3
for r in 1 2; do for b in "$@"; do
  flock /tmp/tamp-build.lock perf stat -x, -e task-clock -r $reps $b $dom $prob --no-check --timeout 29 2>/tmp/r29/ab_ps.txt >/dev/null
  echo "$r $(basename $b) $(grep task-clock /tmp/r29/ab_ps.txt | cut -d, -f1) ms load $(cut -d' ' -f1 /proc/loadavg)"
done; done
