#!/bin/bash
# Issue 14, twenty-ninth round: main's binary (A) against this branch's (B) on the same instances, in turn.
#   pairs.sh OUT BIN_A BIN_B LIST   (LIST: "domain_file problem_file timeout reps" per line)
# Per instance, under one hold of /tmp/tamp-build.lock: rounds 1 and 2 of A then B, each REPS runs
# with the driver's planner arguments (--no-check --timeout T-1 --stats); per run the wall and CPU
# (user+sys) seconds of the process (GNU time), the plan's steps, and the statistics' evaluations
# and expansions; same = 1 when B's plan and counts equal A's in that round.
out=$1; a=$2; b=$3; list=$4
echo "instance,bin,round,run,wall_s,cpu_s,plan_steps,evaluated,expanded,same,load1" > "$out"
while read -r dom prob t reps; do
  name=${prob#*/benchmarks/}; name=${name%.pddl}
  A=$a B=$b DOM=$dom PROB=$prob T=$t REPS=$reps NAME=$name OUT=$out flock /tmp/tamp-build.lock bash -c '
    for r in 1 2; do for x in A B; do for i in $(seq $REPS); do
      /usr/bin/time -f "%e %U %S" -o /tmp/r29/pairs/time.txt ${!x} $DOM $PROB --no-check --timeout $((T-1)) --stats > /tmp/r29/pairs/$x.plan 2> /tmp/r29/pairs/$x.err
      read w u s < <(tail -1 /tmp/r29/pairs/time.txt)
      cpu=$(echo "$u + $s" | bc -l)
      steps=$(grep -c "^(" /tmp/r29/pairs/$x.plan)
      ev=$(grep -o "evaluated [0-9]*" /tmp/r29/pairs/$x.err | cut -d" " -f2)
      ex=$(grep -o "expanded [0-9]*" /tmp/r29/pairs/$x.err | cut -d" " -f2)
      same=""
      if [ $x = B ]; then
        same=$(cmp -s /tmp/r29/pairs/A.plan /tmp/r29/pairs/B.plan && [ "$ev" = "$EVA" ] && [ "$ex" = "$EXA" ] && echo 1 || echo 0)
      else EVA=$ev; EXA=$ex; fi
      echo "$NAME,$x,$r,$i,$w,$cpu,$steps,$ev,$ex,$same,$(cut -d" " -f1 /proc/loadavg)" >> $OUT
    done; done; done'
done < "$list"
