#!/usr/bin/env python3
"""Judges one fault-injection run from its folder (issue 13, part 4): what the report says, what
physically happened (the simulator's action log) and what the effort estimator stored.

    judge_run.py RUN_DIR STORE_SQLITE SERVICE

Prints one tab-separated line:
    status resumptions repeated_ids succeeded_actions stored_records restarts unlogged reason
- repeated_ids: command ids found more than once in the simulator's action log ("none");
- succeeded_actions: the log's succeeded actions; stored_records: distinct execution records in
  the store (-1 when it cannot be read);
- restarts: SERVICE's "restarted" events in events.jsonl;
- unlogged: the report's succeeded command ids missing from the action log ("none").
Used by kill_matrix.sh and two_hosts.sh; `ok` in the last column of --verdict says whether the run
passes: ended succeeded or failed with a reason, nothing executed twice, nothing lost.
"""
import collections
import json
import sqlite3
import sys
from pathlib import Path


def report(run_dir):
    # `tamp run` writes RUN_DIR/report.json, `tamp mission` (two hosts) RUN_DIR/mission/report.json.
    path = run_dir / "report.json"
    if not path.exists() and (run_dir / "mission" / "report.json").exists():
        path = run_dir / "mission" / "report.json"
    try:
        r = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        return "no-report", 0, "no report.json: " + str(e)[:100], []
    reason = (r.get("reason") or "-").replace("\t", " ").replace("\n", " ")[:160]
    return r.get("status", "?"), r.get("resumptions", 0), reason, r.get("actions", [])


def action_log(run_dir):
    try:
        w = json.loads((run_dir / "sim_final_world.json").read_text())
    except (OSError, ValueError):
        return None
    return w.get("action_log", [])


def stored_records(store):
    try:
        return sqlite3.connect(str(store)).execute("select count(distinct record_id) from records").fetchone()[0]
    except (sqlite3.Error, OSError):
        return -1


def restarts(run_dir, service):
    # One events.jsonl per run (`tamp run`), or one per host's launcher in RUN_DIR/HOST/.
    n = 0
    for events in [run_dir / "events.jsonl", *sorted(run_dir.glob("*/events.jsonl"))]:
        try:
            lines = events.read_text().splitlines()
        except OSError:
            continue
        for line in lines:
            try:
                e = json.loads(line)
            except ValueError:
                continue
            if e.get("service") == service and e.get("event") == "restarted":
                n += 1
    return n


def main(argv):
    if len(argv) not in (4, 5) or (len(argv) == 5 and argv[4] != "--verdict"):
        print(__doc__, file=sys.stderr)
        return 30
    run_dir, store, service = Path(argv[1]), Path(argv[2]), argv[3]
    status, resumptions, reason, acts = report(run_dir)
    log = action_log(run_dir)
    if log is None:
        repeated, succeeded, unlogged = "no-world", 0, "-"
    else:
        ids = [a["command_id"] if isinstance(a, dict) else a for a in log]
        rep = [i for i, n in collections.Counter(ids).items() if n > 1]
        repeated = ",".join(rep) if rep else "none"
        succeeded = sum(1 for a in log if isinstance(a, dict) and a.get("outcome") == "succeeded")
        # The robot's log names a command "<mission id>/<command id>", the report "<command id>".
        logged = {i.split("/")[-1] for i in ids}
        lost = [a["command_id"] for a in acts
                if a.get("outcome") == "succeeded" and a.get("command_id") and a["command_id"] not in logged]
        unlogged = ",".join(lost) if lost else "none"
    records = stored_records(store)
    fields = [status, resumptions, repeated, succeeded, records, restarts(run_dir, service), unlogged, reason]
    if len(argv) == 5:
        ok = (repeated == "none" and unlogged == "none" and status in ("succeeded", "failed")
              and not (status == "failed" and reason == "-") and records >= succeeded)
        fields.append("ok" if ok else "bad")
    print("\t".join(str(f) for f in fields))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
