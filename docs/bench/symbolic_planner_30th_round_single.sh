#!/bin/bash
# single.sh TAG "ENV..." SET/DOMAIN/INSTANCE... : one tamp plan run per instance under the lock,
# the driver's planner arguments for pddl-more (--timeout 29 --stats --no-check).
tag=$1; envs=$2; shift 2
D=/work/planner-r30/tests/data/benchmarks
for x in "$@"; do
  set=${x%%/*}; rest=${x#*/}; dom=${rest%%/*}; inst=${rest#*/}
  start=$(date -u +%T); load=$(cut -d' ' -f1 /proc/loadavg)
  line=$(env $envs flock /tmp/tamp-build.lock /usr/bin/time -f "wall %e cpu %U" /tmp/r30/tamp-plan-${BIN:-exp} --timeout ${T:-29} ${EXTRA:-} --stats --no-check $D/$set/$dom/domain.pddl $D/$set/$dom/$inst.pddl 2>&1 >/dev/null | grep -E "^; status|^wall" | tr '\n' ' ')
  echo "$tag $x start $start load $load :: $(echo "$line" | sed -E 's/.*status ([a-z]+);.*expanded ([0-9]+), evaluated ([0-9]+).*(wall .*)/\1 exp \2 eval \3 \4/')"
done
