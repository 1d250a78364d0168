#!/usr/bin/env bash
# kill -9 fault matrix (issue 13, part 4): for each service in turn and each seed, a mission with
# `tamp run` (every service its own process, restarted by tamp run's supervisor when it dies), and a
# SIGKILL to that service at a seeded random point of the mission: the k-th command the robot
# starts (k drawn from the seed among the first --max-step commands), a seeded delay after it
# started, so mid-action kills are the rule. The simulator is in it as the robot driver: its
# process dies, the physical world does not; a restarted simulator resumes from its checkpoint in
# the run folder (sim.checkpoint: the robot, the objects, the action log) and ends the command it
# was running as failed ("robot driver restarted mid-action") instead of executing it again.
#
#   tests/fault/kill_matrix.sh BUILD_DIR [--scenario FILE] [--services "a b ..."] [--seeds "1 2 ..."]
#        [--max-step K] [--out DIR] [--speed F] [--lock FILE]
#
# --lock FILE: each run holds flock(FILE) while it runs (a machine shared with builds and other
# missions: runs never overlap them).
#
# Each run is judged from its run folder: exit code and reason (report.json), the robot's final
# pose and the objects (sim_final_world.json), every command id at most once in the simulator's
# action log, every action the report lists as succeeded in that log (a simulator that forgot
# what the robot did, e.g. one restarted from the scenario, loses them), the execution records in
# the effort estimator's store (one per succeeded action: none lost, none twice), the service's
# restart in events.jsonl. One line per run goes to OUT/matrix.tsv:
#   service seed kill_at_command delay_s killed(yes/no) exit status resumptions repeated_ids
#   succeeded_actions stored_records restarts unlogged reason lost_records phantom_records
#   journal_unlogged verdict
# (unlogged: the report's succeeded command ids missing from the simulator's action log; records
# and the journal matched to the action log by command id: judge_run.py.)
# Exit 0 when every run's kill landed (the service's process was found and killed, and restarted),
# it ended succeeded or failed with a reason, no command id was executed twice, none of the
# report's or the journal's succeeded actions is missing from the action log and no record was
# lost or invented; 1 otherwise (or when nothing ran); 30 on bad arguments.
set -uo pipefail
BUILD=${1:?usage: kill_matrix.sh BUILD_DIR [options]}; shift
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
SCENARIO=$ROOT/config/scenarios/namo_corridor.yaml
SERVICES="graph_manager execution_monitor motion_planner symbolic_planner effort_estimator perception sim"
SEEDS="1 2"
MAX_STEP=4
OUT=${TMPDIR:-/tmp}/tamp-kill-matrix
SPEED=2.0
LOCK=""
while [ $# -gt 0 ]; do
  case $1 in
    --scenario) SCENARIO=$(realpath "$2"); shift 2;;
    --services) SERVICES=$2; shift 2;;
    --seeds) SEEDS=$2; shift 2;;
    --max-step) MAX_STEP=$2; shift 2;;
    --out) OUT=$2; shift 2;;
    --speed) SPEED=$2; shift 2;;
    --lock) LOCK=$2; shift 2;;
    *) echo "kill_matrix.sh: unknown option $1" >&2; exit 30;;
  esac
done
BIN=$(realpath "$BUILD")/bin
[ -x "$BIN/tamp-run" ] || { echo "kill_matrix.sh: no $BIN/tamp-run (build first)" >&2; exit 30; }
[ -f "$SCENARIO" ] || { echo "kill_matrix.sh: no scenario $SCENARIO" >&2; exit 30; }
if ! [[ $MAX_STEP =~ ^[1-9][0-9]*$ ]]; then echo "kill_matrix.sh: --max-step takes a positive integer, got '$MAX_STEP'" >&2; exit 30; fi
mkdir -p "$OUT/deploy/store"
# A deployment like local.yaml with a faster simulator and a fresh effort store (the decisions
# start from the default time models in every run).
sed -E "s/realtime_factor: [0-9.]+/realtime_factor: $SPEED/" "$ROOT/config/services/sim.yaml" > "$OUT/deploy/sim.yaml"
TSV=$OUT/matrix.tsv
printf 'service\tseed\tkill_at_command\tdelay_s\tkilled\texit\tstatus\tresumptions\trepeated_ids\tsucceeded_actions\tstored_records\trestarts\tunlogged\treason\tlost_records\tphantom_records\tjournal_unlogged\tverdict\n' > "$TSV"
bad=0
runs=0
for svc in $SERVICES; do
  for seed in $SEEDS; do
    runs=$((runs + 1))
    RANDOM=$((seed * 7919 + ${#svc}))
    k=$((RANDOM % MAX_STEP + 1))
    delay_ms=$((RANDOM % 2000))
    delay=$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))
    rid="km-$svc-$seed-$$"
    store=$OUT/deploy/store-$rid
    mkdir -p "$store"
    sed -E "s|store_directory: [^#]+|store_directory: $store |" "$ROOT/config/services/effort_estimator.yaml" > "$OUT/deploy/est-$rid.yaml"
    sed -e "s|{config}/services/sim.yaml|$OUT/deploy/sim.yaml|" -e "s|{config}/services/effort_estimator.yaml|$OUT/deploy/est-$rid.yaml|" \
      "$ROOT/config/deploy/local.yaml" > "$OUT/deploy/deploy-$rid.yaml"
    domain=$(( (seed * 13 + runs * 7) % 200 + 20 ))
    log=$OUT/$rid.out
    if [ -n "$LOCK" ]; then exec 9> "$LOCK"; flock 9; fi
    "$BIN/tamp-run" "$SCENARIO" --out "$OUT" --run-id "$rid" --domain "$domain" --deployment "$OUT/deploy/deploy-$rid.yaml" \
      --mission-timeout 400 > "$log" 2>&1 &
    runner=$!
    # The k-th command: once tamp run has printed k-1 finished actions, a seeded delay, then SIGKILL.
    killed=no
    while kill -0 "$runner" 2> /dev/null; do
      finished=$(grep -c '^  (' "$log" 2> /dev/null || true)
      if [ "${finished:-0}" -ge $((k - 1)) ] && grep -q 'tamp run: mission' "$log" 2> /dev/null; then
        sleep "$delay"
        pid=$(pgrep -f -- "tamp_${svc}_service.*$rid" | head -1)
        if [ -n "$pid" ] && kill -9 "$pid" 2> /dev/null; then killed=yes; fi
        break
      fi
      sleep 0.1
    done
    wait "$runner"
    rc=$?
    if [ -n "$LOCK" ]; then flock -u 9; exec 9>&-; fi
    dir=$OUT/$rid
    # What physically happened (the simulator's action log) against the report and the
    # estimator's store (records are de-duplicated by id: a resent one is not stored twice).
    IFS=$'\t' read -r status resumptions repeated succeeded records restarts unlogged reason lost phantom jlost verdict < <(
      python3 "$ROOT/tests/fault/judge_run.py" "$dir" "$store/effort_store.sqlite" "$svc" --verdict)
    # A run whose fault did not land tested nothing: the process was not found (the mission ended
    # before the k-th command, or the service has another name) or was not restarted.
    if [ "$killed" != yes ] || [ "${restarts:-0}" -lt 1 ]; then verdict="bad"; fi
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$svc" "$seed" "$k" "$delay" "$killed" \
      "$rc" "$status" "$resumptions" "$repeated" "$succeeded" "$records" "${restarts:-0}" "$unlogged" "$reason" "$lost" \
      "$phantom" "$jlost" "$verdict" >> "$TSV"
    echo "$svc seed $seed: kill at command $k +${delay}s killed=$killed exit $rc $status repeated=$repeated" \
      "records=$records/$succeeded lost=$lost phantom=$phantom journal_unlogged=$jlost restarts=${restarts:-0}" \
      "unlogged=$unlogged: $verdict"
    [ "$verdict" = ok ] || bad=$((bad + 1))
  done
done
echo "kill_matrix: $runs runs, $bad bad (table: $TSV)"
[ "$runs" -gt 0 ] || exit 1
[ "$bad" -eq 0 ]
