#!/usr/bin/env bash
# A mission across two hosts: two Linux network namespaces ("robot" 10.0.0.2, "workstation"
# 10.0.0.1) joined by a veth link, each running `tamp launch config/deploy/two_hosts.yaml --host
# ...`, the mission sent from the workstation with `tamp mission`. Needs root (ip netns).
#
#   tests/fault/two_hosts.sh BUILD_DIR [--discovery server|servers|multicast] [--scenario FILE]
#        [--netem "loss 10%"|"delay 50ms"|"duplicate 10%"|...] [--partition-at S --partition-for S]
#        [--seed N] [--out DIR] [--run-id ID] [--one-host] [--ping N] [--loss PCT] [--duplicate PCT]
#        [--kill SERVICE --kill-at S] [--kill-launcher HOST --kill-launcher-at S]
#        [--delay MS [--jitter MS]] [--security DIR] [--realtime-factor F]
#
# --realtime-factor F (default 1, real time): the simulator's pace for this run, passed to it as
# $TAMP_SIM_REALTIME_FACTOR through both launchers. The fault matrices of docs/reliability.md were
# measured at real time, so a fault's seconds (--kill-at, --partition-at) land where they did
# there, whatever config/services/sim.yaml's default pace is.
#
# --kill SERVICE --kill-at S: SIGKILL to that service's process S s after the mission started,
# on whichever host runs it (its launcher restarts it). Every run (with or without a fault) is
# judged by tests/fault/judge_run.py (nothing executed twice, no execution record lost or
# invented, the journal's succeeded actions in the robot's log, ended succeeded or failed with a
# reason), its line appended to OUT/RUN_ID/faults.log and the exit code 50 when bad.
#
# --loss PCT / --duplicate PCT drop / duplicate that percentage of the UDP datagrams each host
# sends on the link (nftables `numgen random` on both namespaces' output; needs `nft`, Debian
# package nftables). --netem needs a kernel with sch_netem (CONFIG_NET_SCH_NETEM); the CI VM's
# kernel has none, so loss and duplication go through nftables there and delay through --delay.
#
# --delay MS [--jitter MS]: every UDP datagram each host sends on the link waits MS ms (+- a uniform
# JITTER, order kept) before it leaves, both directions, so a round trip takes 2 MS more. Without
# netem: an iptables NFQUEUE rule in each namespace (the kernel's nft has no `queue` expression
# here, CONFIG_NFT_QUEUE unset; iptables-nft's xt NFQUEUE target works) hands the datagrams to
# tamp_link_delay (tests/fault/link_delay.cc, built when libnetfilter-queue-dev is installed; path
# from $TAMP_LINK_DELAY, default BUILD_DIR/bin), which gives the accept verdict MS ms later. Needs
# `iptables` (Debian package iptables). UDP round trips across the link (tests/fault/udp_rtt.py)
# before and after the delay is on, the delayed packets and the kernel queue's drops go to faults.log.
#
# --kill-launcher HOST --kill-launcher-at S|ready: SIGKILL to that host's `tamp launch` (the
# supervisor, and with it the discovery servers it runs) S s after the mission started, or with
# `ready` before `tamp mission` starts, once every service is ready (`tamp status --json` from
# the workstation): the mission tool is then a participant that must be discovered without that
# host's servers. The host's services go on as orphans (orphan_timeout_s); nothing restarts them.
#
# --security DIR (from deploy/security/make_certs.sh): every participant on both hosts secured.
# --one-host runs both launchers in the workstation namespace (same deployment, discovery and
# UDP profile; traffic stays on the host), the baseline of the two-host benchmark. --ping N: after
# the mission, N round trips of `tamp ping` from the workstation namespace to the simulator (on
# the robot host), written to OUT/RUN_ID/ping.out. Every run gets a fresh effort-estimator store
# (the default time models), so runs take the same decisions.
#
# --discovery server (default): the deployment gets `discovery: {mode: server, servers:
# ["10.0.0.1:11811"], server_host: workstation}` and multicast is removed from the link (the veth
# interfaces lose the MULTICAST flag and have no multicast route), so only the server path can
# discover. --discovery servers: the same without multicast, but a server on each host
# (`servers: ["10.0.0.1:11811", "10.0.0.2:11811"], server_hosts: [workstation, robot]`), every
# participant a client of both. --netem applies `tc qdisc ... netem ARGS` (with the seed) on both ends of the link;
# --partition-at/--partition-for take the link down for that long, that far into the mission.
# Exit code: `tamp mission`'s (0 succeeded, 10 failed, 20 timeout, 30 input, 40 services), and 50
# when the run's checks fail (the simulator's final world is missing), 77 when the network
# namespaces cannot be created (not root: tests skip on it) or --delay cannot be had here (no
# iptables, tamp_link_delay or nfnetlink_queue). Whether the robot reached the goal and
# no command id was executed twice is judged from OUT/RUN_ID/sim_final_world.json
# (tests/fault/two_hosts_test.cc). Artefacts in OUT/RUN_ID.
set -euo pipefail
BUILD=${1:?usage: two_hosts.sh BUILD_DIR [options]}; shift
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
DISCOVERY=server SCENARIO=$ROOT/config/scenarios/namo_corridor_short.yaml NETEM="" SEED=1
PART_AT="" PART_FOR=5 OUT=${TMPDIR:-/tmp}/tamp-two-hosts RUN_ID="" ONE_HOST=0 PING=0 LOSS=0 DUP=0
KILL="" KILL_AT="" KILL_LAUNCHER="" KILL_LAUNCHER_AT="" DELAY="" JITTER=0 SECURITY=""
SPEED=1
QUEUE_NUM=13  # the nfqueue of --delay, one per namespace
while [ $# -gt 0 ]; do
  case $1 in
    --discovery) DISCOVERY=$2; shift 2;;
    --scenario) SCENARIO=$(realpath "$2"); shift 2;;
    --netem) NETEM=$2; shift 2;;
    --partition-at) PART_AT=$2; shift 2;;
    --partition-for) PART_FOR=$2; shift 2;;
    --seed) SEED=$2; shift 2;;
    --out) OUT=$2; shift 2;;
    --run-id) RUN_ID=$2; shift 2;;
    --one-host) ONE_HOST=1; shift;;
    --ping) PING=$2; shift 2;;
    --loss) LOSS=$2; shift 2;;
    --duplicate) DUP=$2; shift 2;;
    --kill) KILL=$2; shift 2;;
    --kill-at) KILL_AT=$2; shift 2;;
    --kill-launcher) KILL_LAUNCHER=$2; shift 2;;
    --kill-launcher-at) KILL_LAUNCHER_AT=$2; shift 2;;
    --delay) DELAY=$2; shift 2;;
    --jitter) JITTER=$2; shift 2;;
    --security) SECURITY=$(realpath "$2"); shift 2;;
    --realtime-factor) SPEED=$2; shift 2;;
    *) echo "two_hosts.sh: unknown option $1" >&2; exit 30;;
  esac
done
[[ $SPEED =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "two_hosts.sh: --realtime-factor takes a number >= 0, got '$SPEED'" >&2; exit 30; }
export TAMP_SIM_REALTIME_FACTOR=$SPEED
case $DISCOVERY in server|servers|multicast) ;; *) echo "two_hosts.sh: --discovery server|servers|multicast, got '$DISCOVERY'" >&2; exit 30;; esac
if [ "$DISCOVERY" = servers ] && [ "$ONE_HOST" = 1 ]; then
  echo "two_hosts.sh: --discovery servers puts a server on each host; not with --one-host" >&2; exit 30
fi
if [ -n "$KILL_LAUNCHER" ]; then
  case $KILL_LAUNCHER in robot|workstation) ;; *) echo "two_hosts.sh: --kill-launcher robot|workstation, got '$KILL_LAUNCHER'" >&2; exit 30;; esac
  [[ $KILL_LAUNCHER_AT =~ ^([0-9]+(\.[0-9]+)?|ready)$ ]] || { echo "two_hosts.sh: --kill-launcher needs --kill-launcher-at SECONDS|ready, got '$KILL_LAUNCHER_AT'" >&2; exit 30; }
fi
SERVICES_ALL="sim perception execution_monitor graph_manager symbolic_planner motion_planner effort_estimator"
if [ -n "$KILL" ]; then
  [[ " $SERVICES_ALL " == *" $KILL "* ]] || { echo "two_hosts.sh: --kill takes one of: $SERVICES_ALL; got '$KILL'" >&2; exit 30; }
  [[ $KILL_AT =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "two_hosts.sh: --kill needs --kill-at SECONDS, got '$KILL_AT'" >&2; exit 30; }
fi
for pct in "$LOSS" "$DUP"; do
  if ! [[ $pct =~ ^[0-9]+$ ]] || [ "$pct" -gt 100 ]; then echo "two_hosts.sh: --loss/--duplicate take a percentage 0..100, got '$pct'" >&2; exit 30; fi
done
if { [ "$LOSS" -gt 0 ] || [ "$DUP" -gt 0 ]; } && ! command -v nft > /dev/null; then
  echo "two_hosts.sh: --loss/--duplicate need nft (Debian package nftables)" >&2; exit 30
fi
if [ -n "$SECURITY" ]; then
  for f in ca.pem governance.p7s; do
    [ -s "$SECURITY/$f" ] || { echo "two_hosts.sh: --security $SECURITY: no $f (make it with deploy/security/make_certs.sh DIR)" >&2; exit 30; }
  done
  # Every participant of both hosts (services, launchers, tamp mission) is secured with its own
  # identity from DIR (tamp::dds::Participant reads $TAMP_DDS_SECURITY).
  export TAMP_DDS_SECURITY=$SECURITY
fi
BIN=$(realpath "$BUILD")/bin
DELAYER=${TAMP_LINK_DELAY:-$BIN/tamp_link_delay}
if [ -n "$DELAY" ]; then
  [[ $DELAY =~ ^[0-9]+(\.[0-9]+)?$ && $JITTER =~ ^[0-9]+(\.[0-9]+)?$ ]] \
    || { echo "two_hosts.sh: --delay/--jitter take milliseconds, got '$DELAY'/'$JITTER'" >&2; exit 30; }
  command -v iptables > /dev/null || { echo "two_hosts.sh: --delay needs iptables (Debian package iptables)" >&2; exit 77; }
  [ -x "$DELAYER" ] || { echo "two_hosts.sh: --delay needs $DELAYER (built from tests/fault/link_delay.cc when libnetfilter-queue-dev is installed; or set TAMP_LINK_DELAY)" >&2; exit 77; }
elif [ "$JITTER" != 0 ]; then
  echo "two_hosts.sh: --jitter needs --delay" >&2; exit 30
fi
TAG=t$$
RUN_ID=${RUN_ID:-twohost-$DISCOVERY-$TAG}
# One two-host run at a time on this machine: ctest starts the TwoHostsTest cases side by side
# (gtest_discover_tests' PRE_TEST discovery leaves RUN_SERIAL unknown when ctest schedules), and
# six deployments on two cores starved one run's execution record past its mission's end (CI of
# session 27). Not /tmp/tamp-build.lock: the CI holds that one around the whole test run.
LOCK=${TAMP_TWO_HOSTS_LOCK:-/tmp/tamp-two-hosts.lock}
exec 9> "$LOCK"
if ! flock -w 420 9; then echo "two_hosts.sh: another two-host run held $LOCK for 420 s" >&2; exit 75; fi
NS_R=tamp-robot-$TAG NS_W=tamp-ws-$TAG
mkdir -p "$OUT/$RUN_ID"
OUT=$(realpath "$OUT")
RUN_DIR=$OUT/$RUN_ID
DEPLOY=$RUN_DIR/deployment.yaml
# A fresh effort-estimator store per run.
mkdir -p "$RUN_DIR/store"
sed -E "s#^store_directory: .*#store_directory: $RUN_DIR/store#" "$ROOT/config/services/effort_estimator.yaml" \
  > "$RUN_DIR/effort_estimator.yaml"
sed -E "s#\{config\}/services/effort_estimator.yaml#$RUN_DIR/effort_estimator.yaml#" \
  "$ROOT/config/deploy/two_hosts.yaml" > "$DEPLOY"
if [ "$DISCOVERY" = server ]; then
  printf 'discovery: {mode: server, servers: ["10.0.0.1:11811"], server_host: workstation}\n' >> "$DEPLOY"
elif [ "$DISCOVERY" = servers ]; then
  printf 'discovery: {mode: server, servers: ["10.0.0.1:11811", "10.0.0.2:11811"], server_hosts: [workstation, robot]}\n' >> "$DEPLOY"
else
  printf 'discovery: {mode: multicast}\n' >> "$DEPLOY"
fi
export TAMP_DOMAIN_ID=$(( (RANDOM % 100) + 100 )) TAMP_DDS_PROFILE=tamp_udp  # SHM would bypass the link

PIDS=()
cleanup() {
  # One after the other, the robot's launcher before the workstation's: the execution monitor
  # hands its last execution records to the effort estimator as it stops (both sides stopped at
  # once lost the mission's last record in the secured CI run of 2026-12-07).
  for p in "${PIDS[@]}"; do kill -TERM "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
  # Services whose launcher was killed (--kill-launcher) are orphans: stopped here, as the launcher
  # would have (the simulator writes its final world on it), waited for at most 10 s.
  local orphans="tamp_[a-z_]*_service --name .*--run-id $RUN_ID( |\$)"
  if pkill -TERM -f -- "$orphans" 2>/dev/null; then
    for _ in $(seq 50); do pgrep -f -- "$orphans" > /dev/null || break; sleep 0.2; done
  fi
  ip netns del "$NS_R" 2>/dev/null || true
  ip netns del "$NS_W" 2>/dev/null || true
}
trap cleanup EXIT

if ! ip netns add "$NS_R" 2> "$RUN_DIR/netns.err" || ! ip netns add "$NS_W" 2>> "$RUN_DIR/netns.err"; then
  echo "two_hosts.sh: cannot create network namespaces (needs root or CAP_SYS_ADMIN and iproute2): $(cat "$RUN_DIR/netns.err")" >&2
  exit 77
fi
ip link add veth-r-$TAG type veth peer name veth-w-$TAG
ip link set veth-r-$TAG netns "$NS_R"
ip link set veth-w-$TAG netns "$NS_W"
ip -n "$NS_R" addr add 10.0.0.2/24 dev veth-r-$TAG
ip -n "$NS_W" addr add 10.0.0.1/24 dev veth-w-$TAG
for ns in "$NS_R" "$NS_W"; do ip -n "$ns" link set lo up; done
ip -n "$NS_R" link set veth-r-$TAG up
ip -n "$NS_W" link set veth-w-$TAG up
if [ "$DISCOVERY" != multicast ]; then
  ip -n "$NS_R" link set veth-r-$TAG multicast off
  ip -n "$NS_W" link set veth-w-$TAG multicast off
  ip -n "$NS_R" link set lo multicast off
  ip -n "$NS_W" link set lo multicast off
  # Prove it: no interface of either host may carry multicast.
  for ns in "$NS_R" "$NS_W"; do
    if ip -n "$ns" -o link show | grep -q MULTICAST; then echo "two_hosts.sh: multicast still on in $ns" >&2; exit 50; fi
  done
else
  ip -n "$NS_R" route add 224.0.0.0/4 dev veth-r-$TAG
  ip -n "$NS_W" route add 224.0.0.0/4 dev veth-w-$TAG
fi
if [ -n "$NETEM" ]; then
  # netem's own random generator takes no seed on Debian 12's tc; the seed labels the run.
  if ! ip netns exec "$NS_R" tc qdisc add dev veth-r-$TAG root netem $NETEM 2> "$RUN_DIR/netem.err"; then
    echo "two_hosts.sh: tc netem $NETEM refused: $(cat "$RUN_DIR/netem.err") (is sch_netem in this kernel?)" >&2; exit 30
  fi
  ip netns exec "$NS_W" tc qdisc add dev veth-w-$TAG root netem $NETEM
fi
# Loss and duplication of the UDP datagrams each side sends on the link (nftables).
link_faults() {  # NS DEV PEER_IP
  local rules=""
  [ "$LOSS" -gt 0 ] && rules+="oifname \"$2\" meta l4proto udp numgen random mod 100 < $LOSS counter drop"$'\n'
  [ "$DUP" -gt 0 ] && rules+="oifname \"$2\" meta l4proto udp numgen random mod 100 < $DUP counter dup to $3 device \"$2\""$'\n'
  [ -z "$rules" ] && return 0
  ip netns exec "$1" nft -f - <<NFT
table ip tamp_fault {
  chain out {
    type filter hook output priority 0; policy accept;
    $rules
  }
}
NFT
}
link_faults "$NS_R" veth-r-$TAG 10.0.0.1
link_faults "$NS_W" veth-w-$TAG 10.0.0.2

# UDP round trips from the workstation to the robot host (tests/fault/udp_rtt.py), into faults.log.
udp_rtt() {  # LABEL
  ip netns exec "$NS_R" python3 "$ROOT/tests/fault/udp_rtt.py" serve 7913 & local server=$!
  sleep 0.3
  echo "udp rtt, $1: $(ip netns exec "$NS_W" python3 "$ROOT/tests/fault/udp_rtt.py" ping 10.0.0.2 7913 20)" >> "$RUN_DIR/faults.log"
  kill "$server"; wait "$server" 2>/dev/null || true
}
# The delay of every UDP datagram NS sends on DEV: tamp_link_delay on the queue, then the rule.
link_delay() {  # NS DEV HOST
  local log=$RUN_DIR/delay-$3.out
  ip netns exec "$1" "$DELAYER" --queue $QUEUE_NUM --delay-ms "$DELAY" --jitter-ms "$JITTER" --seed "$SEED" > "$log" 2>&1 9>&- &
  PIDS+=($!) DELAY_PIDS+=($!)
  local pid=$! rc=0
  for _ in $(seq 50); do grep -q '^ready' "$log" && break; kill -0 $pid 2>/dev/null || break; sleep 0.1; done
  if ! grep -q '^ready' "$log"; then
    kill -0 $pid 2>/dev/null || { wait $pid || rc=$?; }
    echo "two_hosts.sh: tamp_link_delay did not start in $1 (exit $rc): $(cat "$log")" >&2
    [ "$rc" = 31 ] && exit 77  # no nfnetlink_queue or no permission here: tests skip
    exit 30
  fi
  # No --queue-bypass: a datagram nobody can delay is dropped (and counted), never sent early.
  ip netns exec "$1" iptables -A OUTPUT -o "$2" -p udp -j NFQUEUE --queue-num $QUEUE_NUM
}
# Counters of the delay into faults.log; the rules go first, so nothing is queued to a stopped delayer.
stop_link_delay() {
  local ns host
  for ns in "$NS_R" "$NS_W"; do
    host=robot; [ "$ns" = "$NS_W" ] && host=workstation
    echo "$host: iptables $(ip netns exec "$ns" iptables -L OUTPUT -v -n -x | awk '/NFQUEUE/ {print $1 " datagrams to nfqueue " $NF}')" >> "$RUN_DIR/faults.log"
    # /proc/net/netfilter/nfnetlink_queue: queue, portid, waiting, mode, range, queue_dropped, user_dropped, last id
    echo "$host: nfnetlink_queue $(ip netns exec "$ns" awk -v q=$QUEUE_NUM '$1 == q {print "waiting " $3 ", queue_dropped " $6 ", user_dropped " $7}' /proc/net/netfilter/nfnetlink_queue)" >> "$RUN_DIR/faults.log"
    ip netns exec "$ns" iptables -F OUTPUT
  done
  for p in "${DELAY_PIDS[@]}"; do kill -TERM "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
  for host in robot workstation; do echo "$host: $(grep -v '^ready' "$RUN_DIR/delay-$host.out")" >> "$RUN_DIR/faults.log"; done
}
DELAY_PIDS=()
if [ -n "$DELAY" ]; then
  udp_rtt "before the delay"
  link_delay "$NS_R" veth-r-$TAG robot
  link_delay "$NS_W" veth-w-$TAG workstation
  udp_rtt "delay $DELAY ms jitter $JITTER ms each way"
fi

# The simulator (robot host) writes its final ground truth here.
NS_ROBOT_SIDE=$NS_R
[ "$ONE_HOST" = 1 ] && NS_ROBOT_SIDE=$NS_W
ip netns exec "$NS_ROBOT_SIDE" env TAMP_SIM_FINAL_WORLD="$OUT/$RUN_ID/sim_final_world.json" \
  "$BIN/tamp" launch "$DEPLOY" --host robot --run-id "$RUN_ID" --scenario "$SCENARIO" --out "$OUT" \
  > "$OUT/$RUN_ID/launch-robot.out" 2>&1 9>&- &
PIDS+=($!)
ip netns exec "$NS_W" "$BIN/tamp" launch "$DEPLOY" --host workstation --run-id "$RUN_ID" --scenario "$SCENARIO" \
  --out "$OUT" > "$OUT/$RUN_ID/launch-workstation.out" 2>&1 9>&- &
PIDS+=($!)

if [ -n "$PART_AT" ]; then
  (
    # Partition PART_AT s after the mission started (its first status line).
    until grep -q "tamp mission: run" "$OUT/$RUN_ID/mission.out" 2>/dev/null; do sleep 0.2; done
    sleep "$PART_AT"
    ip -n "$NS_W" link set veth-w-$TAG down
    echo "partition: link down at $(date -u +%T.%N)" >> "$OUT/$RUN_ID/faults.log"
    sleep "$PART_FOR"
    ip -n "$NS_W" link set veth-w-$TAG up
    echo "partition: link up at $(date -u +%T.%N)" >> "$OUT/$RUN_ID/faults.log"
  ) &
  PIDS+=($!)
fi

if [ -n "$KILL" ]; then
  (
    # SIGKILL KILL_AT s after the mission started; the service's launcher restarts it.
    until grep -q "tamp mission: run" "$OUT/$RUN_ID/mission.out" 2>/dev/null; do sleep 0.2; done
    sleep "$KILL_AT"
    pid=$(pgrep -f -- "tamp_${KILL}_service --name $KILL .*--run-id $RUN_ID( |\$)" | head -1)
    if [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; then
      echo "kill: SIGKILL to $KILL (pid $pid) at $(date -u +%T.%N)" >> "$OUT/$RUN_ID/faults.log"
    else
      echo "kill: no running $KILL to kill at $(date -u +%T.%N)" >> "$OUT/$RUN_ID/faults.log"
    fi
  ) &
  PIDS+=($!)
fi

# SIGKILL to one host's supervisor (and the discovery servers it runs); nothing restarts it.
kill_launcher() {
  local pid
  pid=$(pgrep -f -- "tamp launch $DEPLOY --host $KILL_LAUNCHER --run-id $RUN_ID" | head -1)
  if [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; then
    echo "kill: SIGKILL to the $KILL_LAUNCHER launcher (pid $pid) at $(date -u +%T.%N)" >> "$OUT/$RUN_ID/faults.log"
  else
    echo "kill: no running $KILL_LAUNCHER launcher to kill at $(date -u +%T.%N)" >> "$OUT/$RUN_ID/faults.log"
  fi
}
# True once every service of the deployment says it is ready (bounded by the caller).
all_ready() {
  ip netns exec "$NS_W" "$BIN/tamp" status --deployment "$DEPLOY" --run-id "$RUN_ID" --json --wait 2 2>/dev/null |
    python3 -c 'import json,sys; j=json.load(sys.stdin); s=j["services"]; sys.exit(0 if s and not j["missing"] and all(x.get("state")=="ready" for x in s) else 1)'
}
if [ "$KILL_LAUNCHER_AT" = ready ]; then
  ready_from=$(date +%s.%N)
  for _ in $(seq 60); do all_ready && break; done
  echo "ready: every service after $(awk "BEGIN{print $(date +%s.%N) - $ready_from}") s" >> "$OUT/$RUN_ID/faults.log"
  kill_launcher
elif [ -n "$KILL_LAUNCHER" ]; then
  (
    until grep -q "tamp mission: run" "$OUT/$RUN_ID/mission.out" 2>/dev/null; do sleep 0.2; done
    sleep "$KILL_LAUNCHER_AT"
    kill_launcher
  ) &
  PIDS+=($!)
fi

START=$(date +%s.%N)
set +e
ip netns exec "$NS_W" "$BIN/tamp" mission "$SCENARIO" --deployment "$DEPLOY" --run-id "$RUN_ID" --seed "$SEED" \
  --mission-timeout 400 --out "$OUT" > "$OUT/$RUN_ID/mission.out" 2>&1
RC=$?
END=$(date +%s.%N)
if [ "$PING" -gt 0 ]; then
  SERVERS=""
  [ "$DISCOVERY" = server ] && SERVERS=10.0.0.1:11811
  [ "$DISCOVERY" = servers ] && SERVERS="10.0.0.1:11811;10.0.0.2:11811"
  ip netns exec "$NS_W" env TAMP_DDS_DISCOVERY_SERVERS=$SERVERS "$BIN/tamp" ping sim --run-id "$RUN_ID" -c "$PING" > "$RUN_DIR/ping.out" 2>&1
  tail -1 "$RUN_DIR/ping.out"
fi
set -e
[ -n "$DELAY" ] && stop_link_delay
if [ "$LOSS" -gt 0 ] || [ "$DUP" -gt 0 ]; then
  for ns in "$NS_R" "$NS_W"; do ip netns exec "$ns" nft list table ip tamp_fault | grep counter >> "$RUN_DIR/faults.log"; done
fi
cat "$OUT/$RUN_ID/mission.out"
echo "two_hosts.sh: run $RUN_ID discovery=$DISCOVERY security=${SECURITY:+on} one_host=$ONE_HOST netem='${NETEM}' loss=$LOSS% duplicate=$DUP% partition_at='${PART_AT}' delay='${DELAY}' jitter=$JITTER seed=$SEED exit=$RC mission_s=$(awk "BEGIN{print $END - $START}")"
cleanup; trap - EXIT
# The simulator writes its final world on a clean stop (cleanup sends SIGTERM to the launchers).
if [ "$RC" = 0 ] && [ ! -s "$OUT/$RUN_ID/sim_final_world.json" ]; then
  echo "two_hosts.sh: mission succeeded but the simulator wrote no final world" >&2; exit 50
fi
# Every run is judged, whatever its fault (a kill, loss, duplication, delay, a partition, none):
# nothing executed twice, nothing lost or invented between the robot's log, the journal and the
# estimator's store.
verdict_line=$(python3 "$ROOT/tests/fault/judge_run.py" "$RUN_DIR" "$RUN_DIR/store/effort_store.sqlite" "${KILL:-none}" --verdict)
echo "judge: ${KILL:+$KILL at +${KILL_AT}s: }$verdict_line" | tee -a "$RUN_DIR/faults.log"
if [ "${verdict_line##*$'\t'}" != ok ]; then echo 50 > "$OUT/$RUN_ID/exit_code"; exit 50; fi
echo "$RC" > "$OUT/$RUN_ID/exit_code"
exit "$RC"
