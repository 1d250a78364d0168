#!/usr/bin/env python3
"""Issue 14, twenty-sixth round: the instances run in pairs (main, then this branch, per instance):
cost, wall time and the anytime phase's counts from the --stats column, against LAMA-first's cost.
usage: symbolic_planner_26th_round_pairs.py PAIRS_CSV BENCH_ROOT"""
import csv, re, sys

rows = list(csv.DictReader(open(sys.argv[1])))
ref = {}
for s in ('pddl-more', 'pddl-adl'):
    for r in csv.DictReader(open(f"{sys.argv[2]}/{s}/reference_results.csv")):
        ref[(r['domain'], r['problem'], r['planner'])] = r
def nbh(st):
    m = re.search(r'plan neighbourhood searches (\d+); (\d+) improvements; up to (\d+) states(?:; ([0-9.]+) s)?', st)
    it = re.search(r'anytime (\d+) iterations; (\d+) improvements', st)
    return (f"{m.group(1)}/{m.group(2)}/{int(m.group(3)) // 1024}k" + (f"/{m.group(4)} s" if m.group(4) else '')
            if m else '–') + (f"; it {it.group(1)}/{it.group(2)}" if it else '')
labels = ['main', 'new', 'trial']  # new: 3b8d314 (citycar) / 4266a28 (parcprinter, sokoban); trial: 35a81cf
print('| instance | cost ' + ' / '.join(labels) + ' / LAMA-first | wall s ' + ' / '.join(labels) +
      ' | neighbourhood searches / improvements / largest (/ time); weighted iterations / improvements: ' + '; '.join(labels) + ' |')
print('|---|---|---|---|')
by = {}
for r in rows:
    by.setdefault((r['domain'], r['problem']), {})[r['planner']] = r
c = lambda r: (r['plan_cost'] or r['plan_length']) if r and r['solved'] == '1' else '–'
for (d, p), x in by.items():
    la = ref.get((d, p, 'fd-lama-first'))
    print(f"| {d}-{p.split('-')[1]} | {' / '.join(c(x.get(l)) for l in labels)} / {c(la)} | "
          f"{' / '.join(x[l]['wall_s'] if l in x else '–' for l in labels)} | "
          f"{'; '.join(nbh(x[l]['stats']) if l in x else '–' for l in labels)} |")
