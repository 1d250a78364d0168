#!/usr/bin/env python3
"""Issue 14, twenty-fifth round: one planner's per-domain driver CSVs against the set's FF 2.3 and
LAMA-first references: coverage, median wall time against each (instances both solve), median
plan cost against LAMA-first's (instances both solve), the instances dearer than LAMA-first's.
usage: symbolic_planner_25th_round_table.py SET_DIR CSV_GLOB"""
import csv, glob, statistics, sys

ref = {}
for r in csv.DictReader(open(sys.argv[1] + '/reference_results.csv')):
    ref[(r['domain'], r['problem'], r['planner'])] = r
ours = {}
for f in sorted(glob.glob(sys.argv[2])):
    for r in csv.DictReader(open(f)):
        ours[(r['domain'], r['problem'])] = r
ok = lambda r: r is not None and r.get('solved') == '1'
cost = lambda r: float(r['plan_cost'] or r['plan_length'])
med = lambda xs, f='{:.3f}': f.format(statistics.median(xs)) if xs else '–'
print('| domain (n) | coverage ours / FF / LAMA | median wall s ours / FF (n both) | median wall s ours / LAMA (n both) '
      '| median cost ours / LAMA (n both) | dearer than LAMA-first |')
print('|---|---|---|---|---|---|')
tot = [0] * 4
for d in sorted({k[0] for k in ours}):
    ks = sorted((k for k in ours if k[0] == d), key=lambda k: int(k[1].split('-')[1]))
    ff = {k: ref.get((d, k[1], 'ff-v2.3')) for k in ks}
    la = {k: ref.get((d, k[1], 'fd-lama-first')) for k in ks}
    c = [sum(ok(x[k]) for k in ks) for x in (ours, ff, la)]
    bf = [k for k in ks if ok(ours[k]) and ok(ff[k])]
    bl = [k for k in ks if ok(ours[k]) and ok(la[k])]
    dear = ', '.join(f"{k[1].split('-')[1]} ({cost(ours[k]):.0f} > {cost(la[k]):.0f})" for k in bl
                     if cost(ours[k]) > cost(la[k])) or '–'
    print(f"| {d} ({len(ks)}) | {c[0]} / {c[1]} / {c[2]} | {med([float(ours[k]['wall_s']) for k in bf])} / "
          f"{med([float(ff[k]['wall_s']) for k in bf])} ({len(bf)}) | {med([float(ours[k]['wall_s']) for k in bl])} / "
          f"{med([float(la[k]['wall_s']) for k in bl])} ({len(bl)}) | {med([cost(ours[k]) for k in bl], '{:.1f}')} / "
          f"{med([cost(la[k]) for k in bl], '{:.1f}')} ({len(bl)}) | {dear} |")
    for i, v in enumerate([len(ks)] + c):
        tot[i] += v
print(f"| **total ({tot[0]})** | **{tot[1]} / {tot[2]} / {tot[3]}** | | | | |")
