#!/usr/bin/env python3
"""Issue 14, thirtieth round: main's driver rows (pddl, pddl-adl) against the latest earlier rows of each
domain: solved, plan length and cost, and the evaluations of the statistics line (the search's
decisions: the same where nothing depends on time).
usage: compare_rows.py NEW_CSV_GLOB"""
import csv, glob, os, re, sys
B = 'docs/bench/'
def ref_file(prefix, d):
    for pat in (f'{prefix}_29th_round_{d}.csv', f'{prefix}_28th_round_{d}.csv', f'{prefix}_27th_round_main_{d}.csv', f'{prefix}_26th_round_main_{d}.csv',
                f'{prefix}_25th_round_5414580_{d}.csv', f'{prefix}_25th_round_main_{d}.csv', f'{prefix}_23rd_round_{d}.csv'):
        if os.path.exists(B + pat): return B + pat
    return None
ev = lambda r: (re.search(r'evaluated (\d+)', r.get('stats') or '') or [None, None])[1]
tot = {'same': 0, 'differ': 0}
for f in sorted(glob.glob(sys.argv[1])):
    new = list(csv.DictReader(open(f)))
    if not new: continue
    d = new[0]['domain']
    prefix = 'symbolic_planner_ipc_adl' if '_adl_' in f else 'symbolic_planner_ipc'
    rf = ref_file(prefix, d)
    if rf is None:
        print(f'{d}: no earlier rows'); continue
    old = {r['problem']: r for r in csv.DictReader(open(rf))}
    same, diffs = 0, []
    for r in new:
        o = old.get(r['problem'])
        if o is None: diffs.append(f"{r['problem']} not in {rf}"); continue
        a = (o['solved'], o['plan_length'], o.get('plan_cost', ''), ev(o))
        b = (r['solved'], r['plan_length'], r.get('plan_cost', ''), ev(r))
        anytime = re.search(r'anytime (\d+) iterations', r.get('stats') or '')
        if a == b: same += 1
        else: diffs.append(f"{r['problem']}: {a} -> {b}" + (' (anytime)' if anytime and anytime.group(1) != '0' else ''))
    tot['same'] += same; tot['differ'] += len(diffs)
    print(f"{d} vs {os.path.basename(rf)}: {same} of {len(new)} the same (solved, length, cost, evaluations)" + ('' if not diffs else '; ' + '; '.join(diffs)))
print(tot)
