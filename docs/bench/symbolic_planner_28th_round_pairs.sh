#!/bin/bash
# Issue 14, twenty-eighth round: two planner configurations on the same instances, in turn.
#   pairs.sh OUT BIN_A BIN_B REPS LIST   (ARGS_A / ARGS_B: extra planner arguments of each side)
# Per instance (LIST: "domain_file problem_file" per line), under /tmp/tamp-build.lock: one run of
# each (their plans compared byte for byte), then A, B, A, B, each as `perf stat -r REPS` (mean
# task-clock) and REPS runs back to back (mean elapsed, from date +%s%N). CSV: instance, side,
# round, task-clock ms, elapsed ms, same plan (1/0), 1-min load.
out=$1; a=$2; b=$3; reps=$4; list=$5
export A="$a $ARGS_A" B="$b $ARGS_B" REPS=$reps
echo "instance,bin,round,task_clock_ms,elapsed_ms,same_plan,load1" > "$out"
while read -r dom prob; do
  name=${prob#*/benchmarks/}; name=${name%.pddl}
  DOM=$dom PROB=$prob NAME=$name OUT=$out flock /tmp/tamp-build.lock bash -c '
    $A $DOM $PROB > /tmp/r28/pa.out 2>/dev/null; $B $DOM $PROB > /tmp/r28/pb.out 2>/dev/null
    same=$(cmp -s /tmp/r28/pa.out /tmp/r28/pb.out && echo 1 || echo 0)
    for r in 1 2; do for x in A B; do
      cmd=${!x}
      perf stat -x, -e task-clock -r $REPS $cmd $DOM $PROB 2>/tmp/r28/ps.txt >/dev/null
      tc=$(grep task-clock /tmp/r28/ps.txt | cut -d, -f1)
      t0=$(date +%s%N); for i in $(seq $REPS); do $cmd $DOM $PROB >/dev/null 2>&1; done; t1=$(date +%s%N)
      el=$(echo "($t1-$t0)/1000000/$REPS" | bc -l)
      echo "$NAME,$x,$r,$tc,$(printf %.3f $el),$same,$(cut -d" " -f1 /proc/loadavg)" >> $OUT
    done; done'
done < "$list"
