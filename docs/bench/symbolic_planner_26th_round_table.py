#!/usr/bin/env python3
"""Issue 14, twenty-sixth round: one planner's per-domain driver CSVs against the set's FF 2.3 and
LAMA-first references, by the issue's aims: coverage per domain against FF's (and the instances FF
solves that we do not), in total against LAMA-first's, median wall time against FF's on the
instances both solve, median plan length (cost) against LAMA-first's on the instances both solve
and the instances dearer than LAMA-first's.
usage: symbolic_planner_26th_round_table.py SET_DIR CSV_GLOB"""
import csv, glob, statistics, sys

ref = {}
for r in csv.DictReader(open(sys.argv[1] + '/reference_results.csv')):
    ref[(r['domain'], r['problem'], r['planner'])] = r
ours = {}
for f in sorted(glob.glob(sys.argv[2])):
    for r in csv.DictReader(open(f)):
        ours[(r['domain'], r['problem'])] = r
ok = lambda r: r is not None and r.get('solved') == '1'
cost = lambda r: float(r.get('plan_cost') or r['plan_length'])
med = lambda xs, f='{:.3f}': f.format(statistics.median(xs)) if xs else '–'
num = lambda k: int(k[1].split('-')[1])
print('| domain (n) | coverage ours / FF / LAMA | FF solves, we do not | median wall s ours / FF (n both) | time aim '
      '| median length ours / LAMA (n both) | dearer than LAMA-first |')
print('|---|---|---|---|---|---|---|')
tot = [0] * 4
for d in sorted({k[0] for k in ours}):
    ks = sorted((k for k in ours if k[0] == d), key=num)
    ff = {k: ref.get((d, k[1], 'ff-v2.3')) for k in ks}
    la = {k: ref.get((d, k[1], 'fd-lama-first')) for k in ks}
    c = [sum(ok(x[k]) for k in ks) for x in (ours, ff, la)]
    lost = ', '.join(str(num(k)) for k in ks if ok(ff[k]) and not ok(ours[k])) or '–'
    bf = [k for k in ks if ok(ours[k]) and ok(ff[k])]
    bl = [k for k in ks if ok(ours[k]) and ok(la[k])]
    mo, mf = [float(ours[k]['wall_s']) for k in bf], [float(ff[k]['wall_s']) for k in bf]
    aim = '–' if not bf else ('met' if statistics.median(mo) <= statistics.median(mf) else '**missed**')
    dear = ', '.join(f"{num(k)} ({cost(ours[k]):.0f} > {cost(la[k]):.0f})" for k in bl
                     if cost(ours[k]) > cost(la[k])) or '–'
    print(f"| {d} ({len(ks)}) | {c[0]} / {c[1]} / {c[2]} | {lost} | {med(mo)} / {med(mf)} ({len(bf)}) | {aim} | "
          f"{med([cost(ours[k]) for k in bl], '{:.1f}')} / {med([cost(la[k]) for k in bl], '{:.1f}')} ({len(bl)}) | {dear} |")
    for i, v in enumerate([len(ks)] + c):
        tot[i] += v
print(f"| **total ({tot[0]})** | **{tot[1]} / {tot[2]} / {tot[3]}** | | | | | |")
