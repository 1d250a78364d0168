#!/usr/bin/env bash
# Mission benchmark (issue 11): every scenario given (default: every shipped scenario) under both
# policies, one `tamp run` each, with a fresh effort-estimator store per run (the default models),
# the simulator at REALTIME_FACTOR x real time (simulated durations are unaffected). Writes one
# CSV row per run and a Markdown table to OUT (default docs/bench/mission_bench.*).
# Exits non-zero when it ran nothing.
#   services/graph_manager/bench/mission_bench.sh [BUILD_DIR] [SCENARIO.yaml ...]
set -euo pipefail
cd "$(dirname "$0")/../../.."
build=${1:-build/release}; shift || true
scenarios=("$@")
if [ ${#scenarios[@]} -eq 0 ]; then scenarios=(config/scenarios/*.yaml); fi
factor=${REALTIME_FACTOR:-3}
out=${OUT:-docs/bench/mission_bench}
work=$(mktemp -d /tmp/tamp_mission_bench.XXXXXX)
mkdir -p "$(dirname "$out")" "$work/store"
sed -E "s/^realtime_factor: [0-9.]+/realtime_factor: $factor/" config/services/sim.yaml > "$work/sim.yaml"
sed -E "s#\{config\}/services/sim.yaml#$work/sim.yaml#; s#\{config\}/services/effort_estimator.yaml#$work/effort_estimator.yaml#" \
  config/deploy/local.yaml > "$work/deploy.yaml"
echo "scenario,policy,exit,status,executed_s,predicted_s,planning_first_s,planning_total_s,planner_calls,motion_calls,effort_calls,replans,objects_moved,prediction_error_pct" > "$out.csv"
runs=0
for sc in "${scenarios[@]}"; do
  for policy in effort infeasible; do
    rm -rf "$work/store" && mkdir -p "$work/store"
    sed -E "s#^store_directory: .*#store_directory: $work/store#" config/services/effort_estimator.yaml > "$work/effort_estimator.yaml"
    rm -rf "$work/run"
    set +e
    "$build/bin/tamp-run" "$sc" --policy "$policy" --out "$work/run" --deployment "$work/deploy.yaml" \
      --domain $((100 + runs % 100)) > "$work/log" 2>&1
    rc=$?
    set -e
    runs=$((runs + 1))
    report=$(ls "$work"/run/run-*/report.json 2>/dev/null | head -1 || true)
    if [ -z "$report" ]; then
      echo "$(basename "$sc" .yaml),$policy,$rc,no report,,,,,,,,,," >> "$out.csv"
      continue
    fi
    python3 - "$report" "$(basename "$sc" .yaml)" "$policy" "$rc" >> "$out.csv" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
ex = r.get("executed_effort_s", 0.0); pr = r.get("predicted_effort_s") or 0.0
err = 100.0 * (pr - ex) / ex if ex > 0 and r["status"] == "succeeded" else float("nan")
print(",".join(str(x) for x in [sys.argv[2], sys.argv[3], sys.argv[4], r["status"], round(ex, 1), round(pr, 1),
      round(r["planning_time_to_first_action_s"], 3), round(r["planning_time_s"], 3), r["planner_calls"],
      r["motion_calls"], r["effort_calls"], r["replans"], " ".join(r["objects_moved"]), round(err, 1)]))
PY
  done
done
rm -rf "$work"
if [ "$runs" -eq 0 ]; then echo "mission_bench: ran nothing" >&2; exit 2; fi
python3 - "$out.csv" > "$out.md" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("| scenario | policy | status | executed s | predicted s | planning to 1st action s | planning total s | planner / motion / effort calls | replans | moved | prediction error % |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['scenario']} | {r['policy']} | {r['status']} | {r['executed_s']} | {r['predicted_s']} | {r['planning_first_s']} | {r['planning_total_s']} | {r['planner_calls']} / {r['motion_calls']} / {r['effort_calls']} | {r['replans']} | {r['objects_moved']} | {r['prediction_error_pct']} |")
ok = sum(1 for r in rows if r["status"] == "succeeded")
print(f"\n{ok} of {len(rows)} runs succeeded.")
PY
cat "$out.md"
