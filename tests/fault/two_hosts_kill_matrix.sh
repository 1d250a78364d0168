#!/usr/bin/env bash
# kill -9 across two hosts (issue 13, part 4): for each service in turn and each seed, a mission
# through tests/fault/two_hosts.sh (robot and workstation network namespaces, discovery server)
# with a SIGKILL to that service at a seeded point of the mission (uniform in [--from, --to] s
# after it started). Each run is judged by tests/fault/judge_run.py: ended succeeded or failed with
# a reason, no command id executed twice, no succeeded action missing from the robot's log, no
# execution record lost. Needs root (ip netns).
#
#   tests/fault/two_hosts_kill_matrix.sh BUILD_DIR [--scenario FILE] [--services "a b ..."]
#        [--seeds "1 2 ..."] [--from S] [--to S] [--out DIR] [--lock FILE]
#
# One line per run goes to OUT/matrix.tsv (service, seed, kill_at_s, exit, then judge_run.py's
# fields). Exit 0 when every run passes, 1 otherwise or when nothing ran, 30 on bad arguments,
# 77 when namespaces cannot be created.
set -uo pipefail
BUILD=${1:?usage: two_hosts_kill_matrix.sh BUILD_DIR [options]}; shift
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
SCENARIO=$ROOT/config/scenarios/namo_corridor.yaml
SERVICES="sim perception execution_monitor graph_manager symbolic_planner motion_planner effort_estimator"
SEEDS="1" FROM=3 TO=40 OUT=${TMPDIR:-/tmp}/tamp-two-hosts-kill LOCK=""
while [ $# -gt 0 ]; do
  case $1 in
    --scenario) SCENARIO=$(realpath "$2"); shift 2;;
    --services) SERVICES=$2; shift 2;;
    --seeds) SEEDS=$2; shift 2;;
    --from) FROM=$2; shift 2;;
    --to) TO=$2; shift 2;;
    --out) OUT=$2; shift 2;;
    --lock) LOCK=$2; shift 2;;
    *) echo "two_hosts_kill_matrix.sh: unknown option $1" >&2; exit 30;;
  esac
done
if ! [[ $FROM =~ ^[0-9]+$ && $TO =~ ^[0-9]+$ ]] || [ "$TO" -le "$FROM" ]; then
  echo "two_hosts_kill_matrix.sh: --from and --to take whole seconds, from < to; got '$FROM' '$TO'" >&2; exit 30
fi
mkdir -p "$OUT"
OUT=$(realpath "$OUT")
TSV=$OUT/matrix.tsv
printf 'service\tseed\tkill_at_s\texit\tstatus\tresumptions\trepeated_ids\tsucceeded_actions\tstored_records\trestarts\tunlogged\treason\tlost_records\tphantom_records\tjournal_unlogged\tverdict\n' > "$TSV"
runs=0 bad=0
for svc in $SERVICES; do
  for seed in $SEEDS; do
    RANDOM=$((seed * 7919 + ${#svc} * 31))
    at=$((FROM + RANDOM % (TO - FROM)))
    rid="thk-$svc-$seed-$$"
    cmd=(bash "$ROOT/tests/fault/two_hosts.sh" "$BUILD" --scenario "$SCENARIO" --seed "$seed" --kill "$svc" --kill-at "$at"
         --out "$OUT" --run-id "$rid")
    if [ -n "$LOCK" ]; then flock "$LOCK" "${cmd[@]}" > "$OUT/$rid.out" 2>&1; else "${cmd[@]}" > "$OUT/$rid.out" 2>&1; fi
    rc=$?
    [ "$rc" = 77 ] && { tail -1 "$OUT/$rid.out" >&2; exit 77; }
    [ "$rc" = 30 ] && { tail -1 "$OUT/$rid.out" >&2; exit 30; }
    runs=$((runs + 1))
    line=$(python3 "$ROOT/tests/fault/judge_run.py" "$OUT/$rid" "$OUT/$rid/store/effort_store.sqlite" "$svc" --verdict)
    printf '%s\t%s\t%s\t%s\t%s\n' "$svc" "$seed" "$at" "$rc" "$line" >> "$TSV"
    echo "$svc seed $seed: SIGKILL at +${at}s, exit $rc: $(grep -h '^kill:' "$OUT/$rid/faults.log" 2>/dev/null | head -1); $line"
    [ "${line##*$'\t'}" = ok ] || bad=$((bad + 1))
  done
done
echo "two_hosts_kill_matrix: $runs runs, $bad bad (table: $TSV)"
[ "$runs" -gt 0 ] || exit 1
[ "$bad" -eq 0 ]
