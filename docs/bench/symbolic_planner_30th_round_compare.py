#!/usr/bin/env python3
"""Issue 14, thirtieth round: the new binary's driver rows against the base rows of each domain
(pddl-more: the twenty-ninth round's sweep, cae4398; pddl and pddl-adl: this round's sweep of main):
solved, plan length and cost, and the evaluations of the statistics line; the lazy search's
part (started or fallen back to) per instance, from the base row's statistics.
usage: symbolic_planner_30th_round_compare.py NEW_CSV_GLOB"""
import csv, glob, os, re, sys
B = 'docs/bench/'
def base_file(f, d):
    if '_more_' in f: return B + f'symbolic_planner_ipc_more_29th_round_{d}.csv'
    if '_adl_' in f: return B + f'symbolic_planner_ipc_adl_30th_round_main_{d}.csv'
    return B + f'symbolic_planner_ipc_30th_round_main_{d}.csv'
ev = lambda r: (re.search(r'evaluated (\d+)', r.get('stats') or '') or [None, None])[1]
lazy = lambda r: bool(re.search(r'lazy search beside|fell back', r.get('stats') or ''))
tot = {'same': 0, 'differ': 0, 'gained': [], 'lost': [], 'lazy_base': 0}
for f in sorted(glob.glob(sys.argv[1])):
    new = list(csv.DictReader(open(f)))
    if not new: continue
    d = new[0]['domain']
    bf = base_file(os.path.basename(f), d)
    old = {r['problem']: r for r in csv.DictReader(open(bf))}
    same, diffs = 0, []
    for r in new:
        o = old[r['problem']]
        tot['lazy_base'] += lazy(o)
        a = (o['solved'], o['plan_length'], o.get('plan_cost', ''), ev(o))
        b = (r['solved'], r['plan_length'], r.get('plan_cost', ''), ev(r))
        if o['solved'] == '0' and r['solved'] == '1': tot['gained'].append(f"{d}-{r['problem'].split('-')[1]}")
        if o['solved'] == '1' and r['solved'] == '0': tot['lost'].append(f"{d}-{r['problem'].split('-')[1]}")
        if a == b: same += 1
        else: diffs.append(f"{r['problem']}: {a} -> {b}" + ('' if lazy(o) else ' (no lazy search in the base)'))
    tot['same'] += same; tot['differ'] += len(diffs)
    print(f"{d} vs {os.path.basename(bf)}: {same} of {len(new)} the same (solved, length, cost, evaluations)" + ('' if not diffs else '; ' + '; '.join(diffs)))
print(tot)
