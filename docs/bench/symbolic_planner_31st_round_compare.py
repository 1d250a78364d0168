#!/usr/bin/env python3
"""Issue 14, thirty-first round: two planners' driver CSVs, instance by instance (solved, plan length, cost,
evaluations of the statistics line, wall time), with the instances that differ listed and the domains'
median wall times on the instances both solve.
usage: symbolic_planner_31st_round_compare.py BASE_CSV_GLOB NEW_CSV_GLOB"""
import csv, glob, re, statistics, sys
ev = lambda r: (re.search(r'evaluated (\d+)', r.get('stats') or '') or [None, None])[1]
def rows(g):
    out = {}
    for f in sorted(glob.glob(g)):
        for r in csv.DictReader(open(f)):
            out[(r['domain'], r['problem'])] = r
    return out
base, new = rows(sys.argv[1]), rows(sys.argv[2])
same, gained, lost = 0, [], []
for d in sorted({k[0] for k in new}):
    ks = sorted((k for k in new if k[0] == d), key=lambda k: int(k[1].split('-')[1]))
    both = [k for k in ks if base[k]['solved'] == '1' and new[k]['solved'] == '1']
    mb = statistics.median(float(base[k]['wall_s']) for k in both) if both else float('nan')
    mn = statistics.median(float(new[k]['wall_s']) for k in both) if both else float('nan')
    diffs = []
    for k in ks:
        b, n = base[k], new[k]
        a = (b['solved'], b['plan_length'], b.get('plan_cost', ''), ev(b))
        c = (n['solved'], n['plan_length'], n.get('plan_cost', ''), ev(n))
        if b['solved'] == '0' and n['solved'] == '1': gained.append(f"{d}-{k[1].split('-')[1]}")
        if b['solved'] == '1' and n['solved'] == '0': lost.append(f"{d}-{k[1].split('-')[1]}")
        if a == c: same += 1
        else: diffs.append(f"{k[1].split('-')[1]}: {a[0]}/{a[1]}/{a[2]}/{a[3]} {float(b['wall_s']):.2f}s -> "
                           f"{c[0]}/{c[1]}/{c[2]}/{c[3]} {float(n['wall_s']):.2f}s")
    print(f"{d}: {len(ks) - len(diffs)} of {len(ks)} the same; median wall on both solved ({len(both)}) "
          f"{mb:.3f} -> {mn:.3f} s" + ('; ' + '; '.join(diffs) if diffs else ''))
print(f"rows the same (solved/length/cost/evaluations): {same} of {len(new)}; gained {gained}; lost {lost}")
