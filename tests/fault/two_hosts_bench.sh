#!/usr/bin/env bash
# One host against two (issue 13, part 2): RUNS missions of SCENARIO with every service in one
# network namespace (`two_hosts.sh --one-host`) and RUNS split across two namespaces joined by a
# veth link (robot side / workstation side), both with the deployment's discovery server and the
# UDPv4 profile, then `tamp ping sim` (PING round trips of 64 B from the workstation namespace).
# Each run is judged by the simulator's final world (robot within 0.10 m of GOAL_X,GOAL_Y).
# One CSV row per run into OUT (default docs/bench/two_hosts.csv, appended; header when new).
#   tests/fault/two_hosts_bench.sh BUILD_DIR [--runs N] [--scenario FILE] [--netem ARGS]
#        [--modes "one two"] [--ping N] [--goal X,Y] [--out CSV]
# $TAMP_LOCK: a lock file each run holds (flock), so that runs do not overlap builds or missions.
set -euo pipefail
BUILD=${1:?usage: two_hosts_bench.sh BUILD_DIR [options]}; shift
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
RUNS=3 SCENARIO=$ROOT/config/scenarios/namo_corridor_short.yaml NETEM="" MODES="one two" PING=200
GOAL=8.5,1.2 CSV=$ROOT/docs/bench/two_hosts.csv
while [ $# -gt 0 ]; do
  case $1 in
    --runs) RUNS=$2; shift 2;;
    --scenario) SCENARIO=$(realpath "$2"); shift 2;;
    --netem) NETEM=$2; shift 2;;
    --modes) MODES=$2; shift 2;;
    --ping) PING=$2; shift 2;;
    --goal) GOAL=$2; shift 2;;
    --out) CSV=$2; shift 2;;
    *) echo "two_hosts_bench.sh: unknown option $1" >&2; exit 30;;
  esac
done
WORK=$(mktemp -d /tmp/tamp_two_hosts_bench.XXXXXX)
mkdir -p "$(dirname "$CSV")"
[ -s "$CSV" ] || echo "date_utc,commit,scenario,hosts,netem,run,exit,at_goal,executed_s,mission_wall_s,ping_n,ping_min_us,ping_median_us,ping_max_us,load1" > "$CSV"
COMMIT=$(git -C "$ROOT" rev-parse --short HEAD)
LOCK=()
[ -n "${TAMP_LOCK:-}" ] && LOCK=(flock "$TAMP_LOCK")
for ((i = 1; i <= RUNS; i++)); do
  for mode in $MODES; do
    opts=(--discovery server --scenario "$SCENARIO" --out "$WORK" --run-id "bench-$mode-$i" --ping "$PING")
    [ "$mode" = one ] && opts+=(--one-host)
    [ -n "$NETEM" ] && opts+=(--netem "$NETEM")
    set +e
    "${LOCK[@]}" "$ROOT/tests/fault/two_hosts.sh" "$BUILD" "${opts[@]}" > "$WORK/bench-$mode-$i.log" 2>&1
    rc=$?
    set -e
    load=$(cut -d' ' -f1 /proc/loadavg)
    dir=$WORK/bench-$mode-$i
    executed=$(jq -r '.executed_effort_s // empty' "$dir/mission/report.json" 2>/dev/null || true)
    wall=$(sed -n 's/^tamp mission: wall time \([0-9.]*\) s$/\1/p' "$dir/mission.out" 2>/dev/null || true)
    at_goal=$(jq -r --arg g "$GOAL" '($g | split(",") | map(tonumber)) as [$x, $y]
      | (((.robot.x - $x) | . * .) + ((.robot.y - $y) | . * .) | sqrt) < 0.10' "$dir/sim_final_world.json" 2>/dev/null || echo false)
    read -r n pmin pmed pmax < <(sed -n 's/^--- sim: \([0-9]*\) round trips, min \([0-9]*\) us, median \([0-9]*\) us, max \([0-9]*\) us$/\1 \2 \3 \4/p' \
      "$dir/ping.out" 2>/dev/null || true) || true
    echo "$(date -u +%FT%TZ),$COMMIT,$(basename "$SCENARIO" .yaml),$mode,${NETEM// /_},$i,$rc,$at_goal,$executed,$wall,${n:-},${pmin:-},${pmed:-},${pmax:-},$load" | tee -a "$CSV"
  done
done
# Keep the artefacts of runs that failed (their report names the reason).
kept=0
for log in "$WORK"/bench-*.log; do
  d=${log%.log}
  if [ "$(cat "$d/exit_code" 2>/dev/null)" != 0 ]; then kept=1; else rm -rf "$d" "$log"; fi
done
if [ "$kept" = 1 ]; then echo "two_hosts_bench.sh: failed runs kept in $WORK" >&2; else rm -rf "$WORK"; fi
