#!/usr/bin/env python3
"""The evaluation runner (issue 12, part 6): `tamp run` on every scenario and NAMO world given,
under each policy and seed, one mission at a time, and the evidence in one Markdown file.

    tools/evaluation/evaluate.py [INPUT ...] [--policies effort,infeasible,oracle] [--seeds 5] [--world-seeds N]
        [--build build/release] [--out docs/evaluation] [--mission-timeout 600] [--quick]
        [--lock FILE] [--realtime-factor 3] [--no-plot] [--keep-runs DIR] [--notes FILE]

INPUT: scenario YAML files (.yaml/.yml), NAMO world files (.json, or a bare .svg: `tamp run`
loads them with the robot scaled in, tamp::world::loadScenario) and folders, searched
recursively for both. In a folder, an .svg that a world .json beside it names as its
`files.geometry_file` is that world's geometry, not a world; other files (README.md, ...) are
listed as skipped. A file given by name that is neither kind, or a path that does not exist, is an
error naming it. Default INPUT: config/scenarios and tests/data/benchmarks/namo (the full matrix).

Every run: a fresh effort-estimator store (the default models), the simulator at REALTIME_FACTOR
x real time (simulated durations are unaffected), `tamp run --seed S --policy P
--mission-timeout T`; the runner kills a run that outlives T + 120 s. A policy that `tamp run
--policy` refuses is reported as `not available`, not dropped. Seeds are 1..N (`tamp run --seed
0` would mean the graph manager's configured seed).

Writes OUT.csv (one row per run), OUT.md (setup, aggregate table per scenario x policy, effort vs
infeasible per scenario, replanning latency, aims vs measured, every run) and OUT_executed_time.svg
/ .png (plot.py, with Debian's python3-matplotlib, installed here with apt-get when missing).
Exit codes: 0 ran something (whatever the missions' outcomes), 2 bad arguments or input, or ran
nothing, 3 the plot could not be made (the tables are written).

--quick: 1 seed and the first policy only (default inputs: config/scenarios/namo_corridor_short.yaml).
--lock FILE: hold an flock on FILE around each `tamp run` (machines shared with builds).
--list: print what would run (kind, label, file) and exit.
--resume CSV: keep the runs of an earlier (stopped) evaluation's CSV and run only the rest; cases
only in the CSV stay in the tables.
"""

import argparse
import csv
import fcntl
import json
import math
import os
import platform
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
# The configuration the services read: $TAMP_CONFIG_DIR when set (a frozen build evaluated with
# its own configuration), else the repository's. The runs' deployment and simulator and estimator
# settings are made from it, so that they match what the binaries accept.
CONFIG = Path(os.environ.get("TAMP_CONFIG_DIR") or REPO / "config")
DEBIAN_PYTHON = "/usr/bin/python3"  # apt's python3-matplotlib is importable from this one only
PLOT_PACKAGE = "python3-matplotlib"
SCENARIO_SUFFIXES = {".yaml", ".yml"}
WORLD_SUFFIXES = {".json", ".svg"}
DEFAULT_POLICIES = ["effort", "infeasible", "oracle"]
KILL_GRACE_S = 120.0  # beyond --mission-timeout before the runner kills a run
LATENCY_AIM_S = 0.300
LATENCY_TARGET_S = 0.100
CSV_FIELDS = ["scenario", "file", "policy", "seed", "exit", "status", "outcome", "executed_s",
              "predicted_s", "planning_s", "planning_first_s", "replans", "latency_p50_s",
              "latency_p95_s", "latencies_s", "planner_calls", "motion_calls", "effort_calls",
              "objects_moved", "wall_s", "reason"]


class InputError(Exception):
    """Bad command-line input: the message names the file or option."""


@dataclass
class Case:
    label: str  # unique name in the tables
    path: Path
    kind: str  # "scenario" or "world"
    resumed_only: bool = False  # known from --resume rows only: nothing new is run for it


@dataclass
class Inputs:
    cases: list = field(default_factory=list)
    skipped: list = field(default_factory=list)  # files in folders that are neither kind


# ---------------------------------------------------------------- inputs


def geometry_files_named_by_worlds(folder):
    """SVGs that a world JSON in `folder` names as its geometry file."""
    named = set()
    for js in folder.glob("*.json"):
        try:
            geometry = json.loads(js.read_text()).get("files", {}).get("geometry_file")
        except (OSError, ValueError, AttributeError):
            continue  # not a world JSON we can read: `tamp run` reports it when it is run
        if isinstance(geometry, str):
            named.add((folder / geometry).resolve())
    return named


def discover_folder(folder, inputs):
    """Scenarios and NAMO worlds under `folder`, recursively, in sorted order."""
    geometry = {}
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        suffix = path.suffix.lower()
        if suffix in SCENARIO_SUFFIXES:
            inputs.cases.append(Case("", path, "scenario"))
        elif suffix == ".json":
            inputs.cases.append(Case("", path, "world"))
        elif suffix == ".svg":
            if path.parent not in geometry:
                geometry[path.parent] = geometry_files_named_by_worlds(path.parent)
            if path.resolve() not in geometry[path.parent]:
                inputs.cases.append(Case("", path, "world"))
        else:
            inputs.skipped.append(path)


def discover(args_inputs):
    """Every case the arguments name; raises InputError for a missing path or an unknown file."""
    inputs = Inputs()
    for arg in args_inputs:
        path = Path(arg)
        if path.is_dir():
            discover_folder(path, inputs)
        elif not path.exists():
            raise InputError(f"{arg}: no such file or folder")
        elif path.suffix.lower() in SCENARIO_SUFFIXES:
            inputs.cases.append(Case("", path, "scenario"))
        elif path.suffix.lower() in WORLD_SUFFIXES:
            inputs.cases.append(Case("", path, "world"))
        else:
            raise InputError(f"{arg}: neither a scenario (.yaml, .yml) nor a NAMO world (.json, .svg)")
    assign_labels(inputs.cases)
    return inputs


def assign_labels(cases):
    """The file's stem; with the suffix, then the parent folder, when stems collide."""
    def collide(names):
        return {n for n in names if names.count(n) > 1}
    for c in cases:
        c.label = c.path.stem
    for make in (lambda c: c.path.name, lambda c: f"{c.path.parent.name}/{c.path.name}", lambda c: str(c.path)):
        dup = collide([c.label for c in cases])
        for c in cases:
            if c.label in dup:
                c.label = make(c)


# ---------------------------------------------------------------- running


@dataclass
class Setup:
    """Files shared by every run: deployment and simulator config with the realtime factor."""
    work: Path
    deployment: Path
    estimator_template: str


def make_setup(work, realtime_factor):
    sim = (CONFIG / "services/sim.yaml").read_text()
    sim, n = re.subn(r"(?m)^realtime_factor: [0-9.]+", f"realtime_factor: {realtime_factor}", sim)
    if n != 1:
        raise InputError("config/services/sim.yaml: no `realtime_factor:` line to set")
    (work / "sim.yaml").write_text(sim)
    deploy = (CONFIG / "deploy/local.yaml").read_text()
    deploy = deploy.replace("{config}/services/sim.yaml", str(work / "sim.yaml"))
    deploy = deploy.replace("{config}/services/effort_estimator.yaml", str(work / "effort_estimator.yaml"))
    (work / "deploy.yaml").write_text(deploy)
    estimator = (CONFIG / "services/effort_estimator.yaml").read_text()
    if not re.search(r"(?m)^store_directory: ", estimator):
        raise InputError("config/services/effort_estimator.yaml: no `store_directory:` line to set")
    return Setup(work, work / "deploy.yaml", estimator)


def fresh_store(setup):
    """An empty estimator store for the next run (the default models)."""
    store = setup.work / "store"
    shutil.rmtree(store, ignore_errors=True)
    store.mkdir()
    text = re.sub(r"(?m)^store_directory: .*", f"store_directory: {store}", setup.estimator_template)
    (setup.work / "effort_estimator.yaml").write_text(text)


class Lock:
    """flock on a file around one run (no-op without a file)."""

    def __init__(self, path):
        self.path = path
        self.fd = None

    def __enter__(self):
        if self.path:
            self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
            fcntl.flock(self.fd, fcntl.LOCK_EX)
        return self

    def __exit__(self, *exc):
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


def run_command(cmd, log, timeout_s):
    """Runs cmd in its own process group, output to `log`; kills the group after timeout_s.
    Returns (exit code or None when killed, wall seconds)."""
    start = time.monotonic()
    with open(log, "w") as out:
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            rc = proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
            rc = None
    return rc, time.monotonic() - start


def policy_available(tamp_run, policy, work):
    """Whether `tamp run --policy POLICY` is accepted. The probe names a deployment that does not
    exist, so an accepted policy ends at that input error before any service starts."""
    log = work / f"probe_{policy}.log"
    rc, _ = run_command([str(tamp_run), "--policy", policy, "--deployment", str(work / "missing.yaml")], log, 60)
    refused = "--policy" in log.read_text(errors="replace")
    return rc is not None and not refused


def percentile(values, q):
    """Linear interpolation between closest ranks (q in [0, 1]); NaN for no values."""
    if not values:
        return math.nan
    v = sorted(values)
    pos = q * (len(v) - 1)
    lo = math.floor(pos)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (pos - lo)


def rounded(v, digits):
    return round(v, digits) if isinstance(v, (int, float)) and not math.isnan(v) else v


def row_from_report(report, base):
    """A CSV row from report.json (docs/report_schema.md)."""
    lat = [e["latency_s"] for e in report.get("replanning", []) if e.get("latency_s") is not None]
    return dict(base, status=report["status"], outcome=report.get("outcome", ""),
                executed_s=rounded(report.get("executed_effort_s", 0.0), 2),
                predicted_s=rounded(report.get("predicted_effort_s"), 2),
                planning_s=rounded(report.get("planning_time_s"), 3),
                planning_first_s=rounded(report.get("planning_time_to_first_action_s"), 3),
                replans=report.get("replans"), latency_p50_s=rounded(percentile(lat, 0.5), 4),
                latency_p95_s=rounded(percentile(lat, 0.95), 4), latencies_s=" ".join(f"{x:.4f}" for x in lat),
                planner_calls=report.get("planner_calls"), motion_calls=report.get("motion_calls"),
                effort_calls=report.get("effort_calls"),
                objects_moved=" ".join(report.get("objects_moved", [])),
                reason=report.get("reason", ""))


def last_line(log):
    lines = [l for l in log.read_text(errors="replace").splitlines() if l.strip()]
    return lines[-1] if lines else ""


def run_one(case, policy, seed, index, opts, setup):
    """One mission; returns its CSV row."""
    base = dict(scenario=case.label, file=str(case.path), policy=policy, seed=seed)
    fresh_store(setup)
    out = setup.work / "run"
    shutil.rmtree(out, ignore_errors=True)
    log = setup.work / "log"
    cmd = [str(opts.tamp_run), str(case.path), "--policy", policy, "--seed", str(seed), "--out", str(out),
           "--deployment", str(setup.deployment), "--domain", str(opts.domain_base + index % 100),
           "--mission-timeout", str(opts.mission_timeout)]
    with Lock(opts.lock):
        rc, wall = run_command(cmd, log, opts.mission_timeout + KILL_GRACE_S)
    base.update(exit="killed" if rc is None else rc, wall_s=round(wall, 1))
    reports = sorted(out.glob("run-*/report.json"))
    if opts.keep_runs:
        keep = Path(opts.keep_runs) / f"{case.label.replace('/', '_')}-{policy}-{seed}"
        shutil.rmtree(keep, ignore_errors=True)
        shutil.copytree(out, keep, dirs_exist_ok=True) if out.exists() else keep.mkdir(parents=True)
        shutil.copy(log, keep / "tamp_run.log")
    if rc is None:
        return dict(base, status="killed", reason=f"outlived --mission-timeout {opts.mission_timeout} s + {KILL_GRACE_S:.0f} s")
    if not reports:
        return dict(base, status="no report", reason=last_line(log))
    return row_from_report(json.loads(reports[0].read_text()), base)


def unavailable_row(case, policy, seed):
    return dict(scenario=case.label, file=str(case.path), policy=policy, seed=seed, status="not available",
                reason=f"tamp run --policy {policy} is refused")


def seeds_for(case, opts):
    return opts.world_seeds if case.kind == "world" else opts.seeds


def file_key(path):
    return str(Path(path).resolve())


def read_resumed(csv_path):
    """Rows of an earlier evaluation's CSV: {(file, policy): {seed: row}}."""
    try:
        with open(csv_path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        raise InputError(f"--resume {csv_path}: {e.strerror}")
    for r in rows:
        missing = [k for k in ("scenario", "file", "policy", "seed", "status") if not r.get(k)]
        if missing:
            raise InputError(f"--resume {csv_path}: a row without `{missing[0]}` (not an evaluate.py CSV)")
    resumed = {}
    for r in rows:
        if r["status"] != "not available":
            resumed.setdefault((file_key(r["file"]), r["policy"]), {})[int(r["seed"])] = r
    return resumed, rows


def add_resumed_cases(inputs, resumed_rows):
    """Cases of resumed rows that the inputs do not name, in front (they ran first)."""
    known = {file_key(c.path) for c in inputs.cases}
    extra = []
    for r in resumed_rows:
        if file_key(r["file"]) not in known:
            known.add(file_key(r["file"]))
            kind = "scenario" if Path(r["file"]).suffix.lower() in SCENARIO_SUFFIXES else "world"
            extra.append(Case(r["scenario"], Path(r["file"]), kind, resumed_only=True))
    inputs.cases[:0] = extra


def matrix(cases, opts, resumed):
    """(case, policy, seed, resumed row or None) in run order: the seeds asked for, and any
    other seed a resumed row has."""
    for case in cases:
        for policy in opts.policies:
            old = resumed.get((file_key(case.path), policy), {})
            seeds = set(old) | (set() if case.resumed_only else set(seeds_for(case, opts)))
            for seed in sorted(seeds):
                yield case, policy, seed, old.get(seed)


def run_matrix(cases, opts, setup, available, after_each, resumed):
    """Every case x policy x seed not resumed; after_each(rows) is called after every run
    (partial results on disk when the evaluation is stopped, to --resume from)."""
    rows = []
    plan = list(matrix(cases, opts, resumed))
    if opts.seed_major:  # seed 1 of every case and policy first (a stable sort keeps their order)
        plan.sort(key=lambda t: t[2])
    index = 0
    for case, policy, seed, old in plan:
        if old is not None:
            rows.append(dict(old, scenario=case.label))
            continue
        if not available[policy]:
            rows.append(unavailable_row(case, policy, seed))
            continue
        index += 1
        row = run_one(case, policy, seed, index, opts, setup)
        rows.append(row)
        print(f"[{len(rows)}/{len(plan)}] {case.label} {policy} seed {seed}: {row['status']}"
              f" (exit {row['exit']}, executed {fmt(row.get('executed_s'))} s, wall {row['wall_s']} s)", flush=True)
        after_each(rows)
    return rows, index


# ---------------------------------------------------------------- tables


def fmt(v, digits=1):
    if v is None or v == "" or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if isinstance(v, float):
        return f"{v:.{digits}f}"
    return str(v)


def med(values):
    return statistics.median(values) if values else math.nan


def numbers(rows, key):
    return [float(r[key]) for r in rows if r.get(key) not in (None, "")
            and not (isinstance(r[key], float) and math.isnan(r[key]))]


def latencies(rows):
    out = []
    for r in rows:
        out += [float(x) for x in str(r.get("latencies_s") or "").split()]
    return out


def ran(rows):
    return [r for r in rows if r["status"] != "not available"]


def succeeded(rows):
    return [r for r in rows if r["status"] == "succeeded"]


def group(rows, *keys):
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in keys), []).append(r)
    return groups


def aggregate_table(rows, cases, policies):
    g = group(rows, "scenario", "policy")
    lines = ["| scenario | policy | success | executed s: median (min-max) | planning s: median | replans: median |"
             " latency s: p50 / p95 | planner calls: median | motion calls: median | wall s: median |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for case in cases:
        for policy in policies:
            rs = g.get((case.label, policy), [])
            if not ran(rs):
                lines.append(f"| {case.label} | {policy} | not available | | | | | | | |")
                continue
            ok = succeeded(rs)
            ex = numbers(ok, "executed_s")
            lat = latencies(rs)
            spread = f" ({fmt(min(ex))}-{fmt(max(ex))})" if len(ex) > 1 else ""
            lines.append(
                f"| {case.label} | {policy} | {len(ok)}/{len(rs)} | {fmt(med(ex))}{spread} |"
                f" {fmt(med(numbers(rs, 'planning_s')), 2)} | {fmt(med(numbers(rs, 'replans')))} |"
                f" {fmt(percentile(lat, 0.5), 3)} / {fmt(percentile(lat, 0.95), 3)} |"
                f" {fmt(med(numbers(rs, 'planner_calls')))} | {fmt(med(numbers(rs, 'motion_calls')))} |"
                f" {fmt(med(numbers(rs, 'wall_s')))} |")
    return lines


@dataclass
class Comparison:
    label: str
    effort: list
    infeasible: list
    ratio: float
    pays: bool  # moving pays: effort moved an object in a successful run, infeasible never did
    slower_beyond_noise: bool


def compare_effort_infeasible(rows, cases):
    """Per scenario: effort's median executed time over infeasible's (successful runs only)."""
    g = group(succeeded(rows), "scenario", "policy")
    out = []
    for case in cases:
        e = numbers(g.get((case.label, "effort"), []), "executed_s")
        i = numbers(g.get((case.label, "infeasible"), []), "executed_s")
        if not e or not i:
            continue
        ratio = med(e) / med(i) if med(i) > 0 else math.nan
        pays = (any(r.get("objects_moved") for r in g.get((case.label, "effort"), []))
                and not any(r.get("objects_moved") for r in g.get((case.label, "infeasible"), [])))
        out.append(Comparison(case.label, e, i, ratio, pays, min(e) > max(i) and ratio > 1.05))
    return out


def effort_over_oracle(rows):
    """Per scenario (in row order): effort's median executed time over oracle's (successful runs)."""
    g = group(succeeded(rows), "scenario", "policy")
    out = []
    for label in dict.fromkeys(r["scenario"] for r in rows):
        e = numbers(g.get((label, "effort"), []), "executed_s")
        o = numbers(g.get((label, "oracle"), []), "executed_s")
        if e and o and med(o) > 0:
            out.append((label, med(e) / med(o)))
    return out


def comparison_table(comps):
    lines = ["| scenario | effort executed s (runs) | infeasible executed s (runs) | effort / infeasible |"
             " moving pays | effort slower beyond noise |",
             "|---|---|---|---|---|---|"]
    for c in comps:
        lines.append(f"| {c.label} | {', '.join(fmt(x) for x in c.effort)} | {', '.join(fmt(x) for x in c.infeasible)} |"
                     f" {fmt(c.ratio, 2)} | {'yes' if c.pays else 'no'} | {'**yes**' if c.slower_beyond_noise else 'no'} |")
    return lines


def latency_lines(rows, policies):
    lines = ["| policy | replanning events with a next command | p50 s | p95 s | max s |", "|---|---|---|---|---|"]
    for policy in policies + ["all"]:
        lat = latencies([r for r in rows if policy == "all" or r["policy"] == policy])
        lines.append(f"| {policy} | {len(lat)} | {fmt(percentile(lat, 0.5), 3)} | {fmt(percentile(lat, 0.95), 3)} |"
                     f" {fmt(max(lat) if lat else math.nan, 3)} |")
    return lines


def aims_lines(rows, comps, available):
    done = ran(rows)
    ok = succeeded(done)
    lines = [f"- **100 % success:** {len(ok)} of {len(done)} runs succeeded"
             f" ({fmt(100.0 * len(ok) / len(done) if done else math.nan)} %)."
             + (" Met." if done and len(ok) == len(done) else " **Not met.**")]
    slower = [c.label for c in comps if c.slower_beyond_noise]
    lines.append(f"- **effort never slower than infeasible beyond noise** (here: every effort run slower than every"
                 f" infeasible run and the medians more than 5 % apart), over {len(comps)} scenarios where both"
                 f" succeeded: " + (f"**not met** in {', '.join(slower)}." if slower else "met."))
    pays = [c for c in comps if c.pays]
    if pays:
        fast = [c for c in pays if c.ratio <= 0.75]
        lines.append(f"- **>= 25 % faster where moving an object pays** (here: scenarios where effort moved an object"
                     f" and infeasible moved none): "
                     + ", ".join(f"{c.label} {fmt(100 * (1 - c.ratio), 0)} %" for c in pays)
                     + (" faster. Met." if len(fast) == len(pays) else f" faster; met in {len(fast)} of {len(pays)}."))
    else:
        lines.append("- **>= 25 % faster where moving an object pays:** no scenario where effort moved an object,"
                     " infeasible none and both succeeded: not measured.")
    if available.get("oracle"):
        within = effort_over_oracle(rows)
        if within:
            met = [label for label, ratio in within if ratio <= 1.10]
            lines.append("- **within 10 % of oracle** (here: effort's median executed time over oracle's, scenarios"
                         " where both succeeded): "
                         + ", ".join(f"{label} {fmt(ratio, 2)}" for label, ratio in within)
                         + f"; met in {len(met)} of {len(within)}.")
        else:
            lines.append("- **within 10 % of oracle:** no scenario where effort and oracle both succeeded:"
                         " not measured.")
    elif "oracle" in available:
        lines.append("- **within 10 % of oracle:** not measurable: `tamp run --policy oracle` is refused"
                     " by this build.")
    else:
        lines.append("- **within 10 % of oracle:** not measured: the oracle policy was not among `--policies`.")
    lat = latencies(done)
    p95 = percentile(lat, 0.95)
    verdict = "no replanning event with a next command: not measured." if not lat else (
        ("met" if p95 < LATENCY_AIM_S else "**not met**") + (", and under the 100 ms target." if p95 < LATENCY_TARGET_S
                                                             else "; the 100 ms target is not met."))
    lines.append(f"- **replanning latency p95 < 300 ms (aim 100 ms):** p95 {fmt(p95, 3)} s over {len(lat)} events: {verdict}")
    return lines


def run_lines(rows):
    lines = ["| scenario | policy | seed | exit | status | executed s | planning s | replans | latency p50 / p95 s |"
             " planner / motion calls | moved | wall s | reason |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        reason = str(r.get("reason") or "").replace("|", "/").replace("\n", " ")
        if len(reason) > 160:
            reason = reason[:157] + "..."
        lines.append(f"| {r['scenario']} | {r['policy']} | {r['seed']} | {fmt(r.get('exit'))} | {r['status']} |"
                     f" {fmt(r.get('executed_s'))} | {fmt(r.get('planning_s'), 2)} | {fmt(r.get('replans'))} |"
                     f" {fmt(r.get('latency_p50_s'), 3)} / {fmt(r.get('latency_p95_s'), 3)} |"
                     f" {fmt(r.get('planner_calls'))} / {fmt(r.get('motion_calls'))} | {r.get('objects_moved') or ''} |"
                     f" {fmt(r.get('wall_s'))} | {reason} |")
    return lines


# ---------------------------------------------------------------- setup facts


def git_commit():
    try:
        head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
        return head + (" (with uncommitted changes)" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def build_type(build):
    cache = Path(build) / "CMakeCache.txt"
    if cache.exists():
        m = re.search(r"(?m)^CMAKE_BUILD_TYPE:STRING=(.*)$", cache.read_text(errors="replace"))
        if m:
            return m.group(1) or "(none)"
    return "unknown"


def cpu_model():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def load_average():
    return " / ".join(f"{x:.2f}" for x in os.getloadavg())


def seed_list(seeds):
    return ", ".join(str(s) for s in seeds)


def setup_lines(opts, inputs, facts):
    scen = sum(1 for c in inputs.cases if c.kind == "scenario")
    return [
        f"- Command: `{facts['command']}`",
        f"- Commit: {facts['commit']}; build `{opts.build}` ({facts['build_type']})",
        f"- Machine: {os.cpu_count()} cores ({facts['cpu']}), {platform.system()} {platform.release()};"
        f" load average (1/5/15 min) {facts['load_start']} at the start, {facts['load_end']} at the end"
        " (other work on the machine included)",
        f"- Started {facts['start']}, {facts['minutes']:.0f} min wall time, {facts['done']} of {facts['planned']}"
        " runs (not-available ones included), missions one at a time"
        + (f" under `flock {opts.lock}`" if opts.lock else ""),
        f"- {scen} scenario files and {len(inputs.cases) - scen} NAMO worlds (robot scaled as `tamp run` does);"
        f" policies {', '.join(opts.policies)}; seeds {seed_list(opts.seeds)} (NAMO worlds: {seed_list(opts.world_seeds)})",
        f"- Simulator at {opts.realtime_factor} x real time (simulated durations are unaffected); a fresh"
        f" effort-estimator store per run; `--mission-timeout {opts.mission_timeout:g}`",
        "- executed s: the report's `executed_effort_s` (simulated seconds, successful runs only in the aggregates);"
        " planning s: `planning_time_s`; latency: `replanning[].latency_s` pooled over the runs"
        " (interpolated percentiles); wall s: the whole `tamp run`, service start-up included",
    ]


def write_markdown(path, opts, inputs, rows, available, facts, plot_name, notes):
    comps = compare_effort_infeasible(rows, inputs.cases)
    md = ["# Evaluation: effort-based planning against the `infeasible` baseline", "",
          f"Generated by `tools/evaluation/evaluate.py`; rerun the command below to reproduce it.", "",
          "## Setup", ""] + setup_lines(opts, inputs, facts)
    if facts.get("resumed"):
        md.append(f"- Resumed: {facts['resumed']} runs kept from `{opts.resume}` (an earlier invocation; its command"
                  " and load are not repeated here)")
    if inputs.skipped:
        md.append(f"- Skipped (neither a scenario nor a world): {', '.join(str(p) for p in inputs.skipped)}")
    missing = [p for p in opts.policies if not available[p]]
    if missing:
        md.append(f"- Not available: {', '.join(missing)} (`tamp run --policy` refuses it)")
    md += ["", "## Aims vs measured", ""] + aims_lines(rows, comps, available)
    if notes:
        md += ["", notes.strip()]
    md += ["", "## Per scenario and policy", ""] + aggregate_table(rows, inputs.cases, opts.policies)
    md += ["", "## Effort vs infeasible", "",
           "Successful runs only; the ratio is of the medians.", ""] + comparison_table(comps)
    md += ["", "## Replanning latency (event to next command)", ""] + latency_lines(ran(rows), opts.policies)
    if plot_name:
        md += ["", "## Executed time", "", f"![executed time per scenario and policy]({plot_name}.svg)", "",
               f"([PNG]({plot_name}.png)) Bars: median over the successful runs; dots: each run; crosses: failed runs"
               " (their executed time until the failure)."]
    md += ["", "## Every run", ""] + run_lines(rows)
    Path(path).write_text("\n".join(md) + "\n")


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None or (isinstance(r.get(k), float) and math.isnan(r[k])) else r[k])
                        for k in CSV_FIELDS})


# ---------------------------------------------------------------- plot


def debian_package_installed(name):
    res = subprocess.run(["dpkg-query", "-W", "-f=${Status}", name], capture_output=True, text=True)
    return res.returncode == 0 and res.stdout.strip() == "install ok installed"


def ensure_debian_package(name):
    """Installs `name` with apt-get unless dpkg has it; returns an error message or None."""
    if debian_package_installed(name):
        return None
    if os.geteuid() != 0:
        return f"{name} is not installed and this is not root: install it with `apt-get install {name}`"
    print(f"evaluate: installing {name} (apt-get)", flush=True)
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    res = subprocess.run(["apt-get", "install", "-y", "--no-install-recommends", name], env=env)
    if res.returncode != 0:
        subprocess.run(["apt-get", "update"], env=env)
        res = subprocess.run(["apt-get", "install", "-y", "--no-install-recommends", name], env=env)
    return None if res.returncode == 0 and debian_package_installed(name) else f"apt-get install {name} failed"


def make_plot(csv_path, out_stem):
    """OUT_executed_time.svg/.png; returns an error message or None."""
    error = ensure_debian_package(PLOT_PACKAGE)
    if error:
        return error
    res = subprocess.run([DEBIAN_PYTHON, str(Path(__file__).with_name("plot.py")), str(csv_path), str(out_stem)])
    return None if res.returncode == 0 else f"plot.py failed (exit {res.returncode})"


# ---------------------------------------------------------------- main


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("inputs", nargs="*", help="scenario YAML, NAMO world (.json/.svg) or folder")
    p.add_argument("--policies", default=",".join(DEFAULT_POLICIES), help="comma-separated (default: %(default)s)")
    p.add_argument("--seeds", type=int, default=5, help="seeds 1..N (default: %(default)s)")
    p.add_argument("--world-seeds", type=int, default=None,
                   help="seeds 1..N for NAMO world inputs (default: --seeds)")
    p.add_argument("--build", default="build/release", help="build directory with bin/tamp-run (default: %(default)s)")
    p.add_argument("--out", default="docs/evaluation", help="output prefix: OUT.md, OUT.csv, OUT_executed_time.svg/png")
    p.add_argument("--mission-timeout", type=float, default=600.0, help="tamp run --mission-timeout, s")
    p.add_argument("--quick", action="store_true", help="1 seed, the first policy (smoke runs)")
    p.add_argument("--lock", default="", help="flock this file around each tamp run")
    p.add_argument("--realtime-factor", type=float, default=float(os.environ.get("REALTIME_FACTOR", "3")),
                   help="simulator pace (default: $REALTIME_FACTOR or 3)")
    p.add_argument("--domain-base", type=int, default=100, help="DDS domains domain-base + run %% 100")
    p.add_argument("--no-plot", action="store_true", help="tables only")
    p.add_argument("--list", action="store_true", help="print the scenarios and worlds that would run, then exit")
    p.add_argument("--keep-runs", default="", help="copy every run folder (reports, logs) under this folder")
    p.add_argument("--seed-major", action="store_true",
                   help="run seed 1 of every case and policy, then seed 2, ... (an evaluation stopped "
                        "early, or resumed across days, has every case at the same depth)")
    p.add_argument("--resume", default="", help="CSV of an earlier evaluation: its runs are kept, not run again")
    p.add_argument("--notes", default="", help="Markdown file inserted after the aims section")
    opts = p.parse_args(argv)
    opts.command = " ".join([Path(sys.argv[0]).as_posix()] + argv)
    opts.policies = [x for x in opts.policies.split(",") if x]
    if not opts.policies:
        raise InputError("--policies: no policy given")
    if opts.world_seeds is None:
        opts.world_seeds = opts.seeds
    if opts.seeds < 1 or opts.world_seeds < 1:
        raise InputError(f"--seeds {opts.seeds}, --world-seeds {opts.world_seeds}: must be at least 1")
    if opts.mission_timeout <= 0:
        raise InputError(f"--mission-timeout {opts.mission_timeout}: must be positive")
    if opts.realtime_factor < 0:
        raise InputError(f"--realtime-factor {opts.realtime_factor}: must be >= 0 (0: as fast as possible)")
    if not 0 <= opts.domain_base <= 132:
        raise InputError(f"--domain-base {opts.domain_base}: must be in [0, 132]")
    if opts.notes and not Path(opts.notes).is_file():
        raise InputError(f"--notes {opts.notes}: no such file")
    if opts.quick:
        opts.seeds = opts.world_seeds = 1
        opts.policies = opts.policies[:1]
        if not opts.inputs:
            opts.inputs = [str(REPO / "config/scenarios/namo_corridor_short.yaml")]
    if not opts.inputs:
        opts.inputs = [str(REPO / "config/scenarios"), str(REPO / "tests/data/benchmarks/namo")]
    opts.seeds = list(range(1, opts.seeds + 1))
    opts.world_seeds = list(range(1, opts.world_seeds + 1))
    opts.tamp_run = Path(opts.build) / "bin" / "tamp-run"
    if not opts.list and not os.access(opts.tamp_run, os.X_OK):
        raise InputError(f"--build {opts.build}: no executable {opts.tamp_run}")
    return opts


def main(argv):
    try:
        opts = parse_args(argv)
        inputs = discover(opts.inputs)
    except InputError as e:
        print(f"evaluate: {e}", file=sys.stderr)
        return 2
    for p in inputs.skipped:
        print(f"evaluate: skipped {p} (neither a scenario nor a world)", file=sys.stderr)
    if not inputs.cases:
        print(f"evaluate: ran nothing: no scenario or world in {' '.join(opts.inputs)}", file=sys.stderr)
        return 2
    resumed, resumed_rows = {}, []
    if opts.resume:
        try:
            resumed, resumed_rows = read_resumed(opts.resume)
        except InputError as e:
            print(f"evaluate: {e}", file=sys.stderr)
            return 2
        add_resumed_cases(inputs, resumed_rows)
    if opts.list:
        for c in inputs.cases:
            print(f"{c.kind}\t{c.label}\t{c.path}")
        return 0
    facts = dict(command=opts.command, commit=git_commit(), build_type=build_type(opts.build), cpu=cpu_model(),
                 load_start=load_average(), start=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
    facts["planned"] = len(list(matrix(inputs.cases, opts, resumed)))
    facts["resumed"] = sum(len(v) for v in resumed.values())
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="tamp_evaluate.") as tmp:
        work = Path(tmp)
        try:
            setup = make_setup(work, opts.realtime_factor)
        except InputError as e:
            print(f"evaluate: {e}", file=sys.stderr)
            return 2
        available = {p: policy_available(opts.tamp_run, p, work) for p in opts.policies}
        for p in opts.policies:
            if not available[p]:
                print(f"evaluate: policy {p}: not available (tamp run --policy refuses it)", file=sys.stderr)
        out = Path(opts.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        notes = Path(opts.notes).read_text() if opts.notes else ""

        def write_tables(rows_so_far, plot_name=""):
            facts.update(load_end=load_average(), minutes=(time.monotonic() - t0) / 60.0, done=len(rows_so_far))
            write_csv(out.with_suffix(".csv"), rows_so_far)
            write_markdown(out.with_suffix(".md"), opts, inputs, rows_so_far, available, facts, plot_name, notes)

        rows, runs = run_matrix(inputs.cases, opts, setup, available, write_tables, resumed)
    write_tables(rows)
    plot_stem = out.parent / f"{out.name}_executed_time"
    plotted = not opts.no_plot and len(ran(rows)) > 0
    plot_error = make_plot(out.with_suffix(".csv"), plot_stem) if plotted else None
    plot_name = plot_stem.name if plotted and not plot_error else ""
    write_tables(rows, plot_name)
    print(f"evaluate: {runs} runs; wrote {out.with_suffix('.md')}, {out.with_suffix('.csv')}", flush=True)
    if runs == 0 and not resumed:
        print("evaluate: ran nothing (no policy available)", file=sys.stderr)
        return 2
    if plot_error:
        print(f"evaluate: no plot: {plot_error}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
