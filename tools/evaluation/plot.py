#!/usr/bin/python3
"""Executed time per scenario and policy, from evaluate.py's CSV: STEM.svg and STEM.png.

    /usr/bin/python3 tools/evaluation/plot.py OUT.csv STEM

Horizontal bars: the median executed time (simulated s) over the successful runs of each scenario
and policy; dots: each successful run; crosses: failed runs at the executed time they reached.
Needs Debian's python3-matplotlib (evaluate.py installs it).
"""

import csv
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b"]


def load(csv_path):
    rows = [r for r in csv.DictReader(open(csv_path)) if r["status"] != "not available"]
    scenarios = list(dict.fromkeys(r["scenario"] for r in rows))
    policies = list(dict.fromkeys(r["policy"] for r in rows))
    return rows, scenarios, policies


def executed(rows, scenario, policy, ok):
    return [float(r["executed_s"]) for r in rows
            if r["scenario"] == scenario and r["policy"] == policy and (r["status"] == "succeeded") == ok
            and r["executed_s"] != ""]


def main(csv_path, stem):
    rows, scenarios, policies = load(csv_path)
    if not rows:
        print("plot.py: no runs in " + csv_path, file=sys.stderr)
        return 2
    height = 0.8 / len(policies)
    fig, ax = plt.subplots(figsize=(9, 1.0 + 0.32 * len(scenarios) * len(policies)))
    labelled = set()
    for k, policy in enumerate(policies):
        colour = COLOURS[k % len(COLOURS)]
        for i, scenario in enumerate(scenarios):
            y = i + (k - (len(policies) - 1) / 2) * height
            ok = executed(rows, scenario, policy, True)
            bad = executed(rows, scenario, policy, False)
            if ok:
                ax.barh(y, statistics.median(ok), height=height * 0.9, color=colour, alpha=0.6,
                        label=policy if policy not in labelled else None)
                labelled.add(policy)
                ax.plot(ok, [y] * len(ok), "o", color=colour, markersize=3)
            if bad:
                ax.plot(bad, [y] * len(bad), "x", color="#d62728", markersize=6)
    handles, labels = ax.get_legend_handles_labels()
    seen = dict(zip(labels, handles))
    if any(r["status"] != "succeeded" for r in rows):
        seen["failed run"] = ax.plot([], [], "x", color="#d62728")[0]
    ax.legend(seen.values(), seen.keys(), loc="best", fontsize=8)
    ax.set_yticks(range(len(scenarios)))
    ax.set_yticklabels(scenarios, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("executed time (simulated s)")
    ax.set_title("Executed time per scenario and policy")
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    fig.savefig(stem + ".svg")
    fig.savefig(stem + ".png", dpi=120)
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
