#!/bin/bash
# probe.sh BIN LIMIT "extra args" inst... ; inst = set/domain/N ; one hold of the lock for the list
cd /work/planner31
b=$1; lim=$2; extra=$3; shift 3
flock /tmp/tamp-build.lock bash -c '
b=$1; lim=$2; extra=$3; shift 3
for i in "$@"; do
  set=${i%%/*}; rest=${i#*/}; d=${rest%%/*}; n=${rest#*/}
  base=tests/data/benchmarks/$set/$d
  if [ -d $base/instance-$n ]; then dom=$base/instance-$n/domain.pddl; prob=$base/instance-$n/instance-$n.pddl; else dom=$base/domain.pddl; prob=$base/instance-$n.pddl; fi
  s=$(date +%s.%N)
  out=$(timeout $((lim+1)) /tmp/p31/tamp-plan-$b $dom $prob --timeout $lim --stats --no-check $extra 2>&1 >/dev/null | grep "; status")
  e=$(date +%s.%N)
  st=$(echo "$out" | sed -E "s/.*status ([a-z ]+);.*/\1/"); ev=$(echo "$out" | sed -E "s/.*evaluated ([0-9]+).*/\1/")
  printf "%-28s %-6s %-24s %-10s %8.2f s evals %s load %s\n" "$i" "$b" "$extra" "$st" $(echo "$e - $s" | bc) "$ev" "$(cut -d" " -f1 /proc/loadavg)"
done' probe "$b" "$lim" "$extra" "$@"
