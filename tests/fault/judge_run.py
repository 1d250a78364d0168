#!/usr/bin/env python3
"""Judges one fault-injection run from its folder (issue 13, part 4): what the report says, what
physically happened (the simulator's action log) and what the effort estimator stored.

    judge_run.py RUN_DIR STORE_SQLITE SERVICE

Prints one tab-separated line:
    status resumptions repeated_ids succeeded_actions stored_records restarts unlogged reason
        [lost_records phantom_records journal_unlogged verdict]
- repeated_ids: command ids found more than once in the simulator's action log ("none");
- succeeded_actions: the log's succeeded actions; stored_records: distinct execution records in
  the store (-1 when it cannot be read);
- restarts: SERVICE's "restarted" events in events.jsonl;
- unlogged: the report's succeeded command ids missing from the action log ("none").
With --verdict, matched by id (a record's id is its command's id):
- lost_records: commands the action log says succeeded that have no record in the store;
- phantom_records: records in the store of commands the action log does not have;
- journal_unlogged: commands the graph manager's journal says succeeded that the action log lacks
  (what a restarted graph manager believes the robot did, against what it did);
and `ok` or `bad`: the run passes when it ended succeeded or failed with a reason, no command
was executed twice, and nothing was lost or invented on either side.
Used by kill_matrix.sh and two_hosts.sh.
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


def stored_ids(store):
    """The store's record ids, or None when it cannot be read."""
    if not Path(store).exists():
        return None
    try:
        return {r[0] for r in sqlite3.connect(str(store)).execute("select distinct record_id from records")}
    except (sqlite3.Error, OSError):
        return None


def journal_succeeded(run_dir):
    """Command ids the graph manager's journal says succeeded ("<command id>", no mission id)."""
    for path in [run_dir / "graph_manager.journal.json", *sorted(run_dir.glob("*/graph_manager.journal.json"))]:
        try:
            j = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        return [a["command_id"] for a in j.get("actions", []) if a.get("outcome") == "succeeded" and a.get("command_id")]
    return None


def joined(ids):
    return ",".join(sorted(ids)) if ids else "none"


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
    records = stored_ids(store)
    lost = phantom = journal_lost = "-"
    if log is None:
        repeated, succeeded, unlogged = "no-world", 0, "-"
    else:
        ids = [a["command_id"] if isinstance(a, dict) else a for a in log]
        rep = [i for i, n in collections.Counter(ids).items() if n > 1]
        repeated = ",".join(rep) if rep else "none"
        done = [a["command_id"] for a in log if isinstance(a, dict) and a.get("outcome") == "succeeded"]
        succeeded = len(done)
        # The robot's log names a command "<mission id>/<command id>", the report "<command id>".
        logged = {i.split("/")[-1] for i in ids}
        unlogged = joined([a["command_id"] for a in acts
                           if a.get("outcome") == "succeeded" and a.get("command_id") and a["command_id"] not in logged])
        if records is not None:
            lost = joined(set(done) - records)
            phantom = joined(records - set(ids))
        journal = journal_succeeded(run_dir)
        if journal is not None:
            journal_lost = joined([c for c in journal if c not in logged])
    fields = [status, resumptions, repeated, succeeded, len(records) if records is not None else -1,
              restarts(run_dir, service), unlogged, reason]
    if len(argv) == 5:
        ok = (repeated == "none" and unlogged == "none" and status in ("succeeded", "failed")
              and not (status == "failed" and reason == "-") and lost == "none" and phantom == "none"
              and journal_lost in ("none", "-"))
        fields += [lost, phantom, journal_lost, "ok" if ok else "bad"]
    print("\t".join(str(f) for f in fields))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
