#!/usr/bin/env bash
# Network-fault matrix (issue 13, part 4): missions across the two hosts of tests/fault/two_hosts.sh
# (robot and workstation network namespaces, discovery server, no multicast) with, in turn, each
# fault on the link, per seed:
#   loss       10 % of the UDP datagrams each host sends dropped (--loss 10)
#   duplicate  10 % of them sent twice (--duplicate 10)
#   delay      every datagram held 50 ms each way (--delay 50)
#   partition  the link down for --partition-for s (default 5) at a seeded point of the mission
# Each run is judged by tests/fault/judge_run.py (through two_hosts.sh): ended succeeded or failed
# with a reason, no command executed twice, no execution record lost or invented, the journal's
# succeeded actions in the robot's log. Needs root (ip netns) and nftables / iptables.
#
#   tests/fault/network_matrix.sh BUILD_DIR [--scenario FILE] [--faults "loss duplicate delay partition"]
#        [--seeds "1 2 ..."] [--from S] [--to S] [--partition-for S] [--out DIR] [--lock FILE]
#
# One line per run goes to OUT/matrix.tsv: fault, seed, its arguments, two_hosts.sh's exit code,
# then judge_run.py's fields (the last one ok / bad). Exit 0 when every run passes, 1 otherwise or
# when nothing ran, 30 on bad arguments, 77 when the namespaces or a fault cannot be had here.
set -uo pipefail
BUILD=${1:?usage: network_matrix.sh BUILD_DIR [options]}; shift
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
SCENARIO=$ROOT/config/scenarios/namo_corridor.yaml
FAULTS="loss duplicate delay partition"
SEEDS="1" FROM=5 TO=30 PART_FOR=5 OUT=${TMPDIR:-/tmp}/tamp-network-matrix LOCK=""
while [ $# -gt 0 ]; do
  case $1 in
    --scenario) SCENARIO=$(realpath "$2"); shift 2;;
    --faults) FAULTS=$2; shift 2;;
    --seeds) SEEDS=$2; shift 2;;
    --from) FROM=$2; shift 2;;
    --to) TO=$2; shift 2;;
    --partition-for) PART_FOR=$2; shift 2;;
    --out) OUT=$2; shift 2;;
    --lock) LOCK=$2; shift 2;;
    *) echo "network_matrix.sh: unknown option $1" >&2; exit 30;;
  esac
done
if ! [[ $FROM =~ ^[0-9]+$ && $TO =~ ^[0-9]+$ && $PART_FOR =~ ^[0-9]+$ ]] || [ "$TO" -le "$FROM" ]; then
  echo "network_matrix.sh: --from, --to and --partition-for take whole seconds, from < to; got '$FROM' '$TO' '$PART_FOR'" >&2
  exit 30
fi
for f in $FAULTS; do
  case $f in loss|duplicate|delay|partition) ;; *) echo "network_matrix.sh: unknown fault '$f' (loss duplicate delay partition)" >&2; exit 30;; esac
done
mkdir -p "$OUT"
OUT=$(realpath "$OUT")
TSV=$OUT/matrix.tsv
printf 'fault\tseed\targs\texit\tstatus\tresumptions\trepeated_ids\tsucceeded_actions\tstored_records\trestarts\tunlogged\treason\tlost_records\tphantom_records\tjournal_unlogged\tverdict\n' > "$TSV"
runs=0 bad=0
for fault in $FAULTS; do
  for seed in $SEEDS; do
    RANDOM=$((seed * 7919 + ${#fault} * 31))
    case $fault in
      loss) args=(--loss 10);;
      duplicate) args=(--duplicate 10);;
      delay) args=(--delay 50);;
      partition) args=(--partition-at $((FROM + RANDOM % (TO - FROM))) --partition-for "$PART_FOR");;
    esac
    rid="net-$fault-$seed-$$"
    cmd=(bash "$ROOT/tests/fault/two_hosts.sh" "$BUILD" --scenario "$SCENARIO" --seed "$seed" "${args[@]}"
         --out "$OUT" --run-id "$rid")
    if [ -n "$LOCK" ]; then flock "$LOCK" "${cmd[@]}" > "$OUT/$rid.out" 2>&1; else "${cmd[@]}" > "$OUT/$rid.out" 2>&1; fi
    rc=$?
    [ "$rc" = 30 ] && { tail -1 "$OUT/$rid.out" >&2; exit 30; }
    [ "$rc" = 77 ] && { tail -1 "$OUT/$rid.out" >&2; exit 77; }
    runs=$((runs + 1))
    line=$(grep -h '^judge: ' "$OUT/$rid/faults.log" 2> /dev/null | tail -1 | sed 's/^judge: //')
    [ -n "$line" ] || line="no-judge"
    printf '%s\t%s\t%s\t%s\t%s\n' "$fault" "$seed" "${args[*]}" "$rc" "$line" >> "$TSV"
    echo "$fault seed $seed (${args[*]}): exit $rc; $line"
    [ "${line##*$'\t'}" = ok ] || bad=$((bad + 1))
  done
done
echo "network_matrix: $runs runs, $bad bad (table: $TSV)"
[ "$runs" -gt 0 ] || exit 1
[ "$bad" -eq 0 ]
