#!/usr/bin/env python3
"""Issue 14, twenty-fifth round: per-domain table of two planner runs (per-domain driver CSVs)
with the FF 2.3 and LAMA-first references of the set: coverage, median wall time, median plan
cost over the instances all three solve, and the instances where a run's cost is above LAMA-first's.
usage: symbolic_planner_25th_round_compare.py SET_DIR A_CSV_GLOB B_CSV_GLOB [A_NAME B_NAME]"""
import csv, glob, statistics, sys


def rows(pattern):
    out = {}
    for f in sorted(glob.glob(pattern)):
        for r in csv.DictReader(open(f)):
            out[(r['domain'], r['problem'])] = r
    return out


def med(xs, fmt='{:.3f}'):
    return fmt.format(statistics.median(xs)) if xs else '–'


def cost(r):
    return float(r['plan_cost'] or r['plan_length'])


ref = {}
for r in csv.DictReader(open(sys.argv[1] + '/reference_results.csv')):
    ref[(r['domain'], r['problem'], r['planner'])] = r
a, b = rows(sys.argv[2]), rows(sys.argv[3])
na, nb = (sys.argv[4], sys.argv[5]) if len(sys.argv) > 5 else ('A', 'B')
keys = sorted(set(a) & set(b), key=lambda k: (k[0], int(k[1].split('-')[1])))
ok = lambda r: r is not None and r.get('solved') == '1'
print(f'| domain (n) | coverage {na} / {nb} / FF / LAMA | median wall s {na} / {nb} (n both) | '
      f'median cost {na} / {nb} / LAMA (n all three) | cost above LAMA-first\'s: {na}; {nb} | cost {na} -> {nb} where it differs | gained / lost |')
print('|---|---|---|---|---|---|---|')
tot = [0] * 5
for d in sorted({k[0] for k in keys}):
    ks = [k for k in keys if k[0] == d]
    lama = {k: ref.get((d, k[1], 'fd-lama-first')) for k in ks}
    ff = {k: ref.get((d, k[1], 'ff-v2.3')) for k in ks}
    ca, cb = sum(ok(a[k]) for k in ks), sum(ok(b[k]) for k in ks)
    cf, cl = sum(ok(ff[k]) for k in ks), sum(ok(lama[k]) for k in ks)
    both = [k for k in ks if ok(a[k]) and ok(b[k])]
    three = [k for k in both if ok(lama[k])]
    above = lambda run: ', '.join(f"{k[1].split('-')[1]} ({cost(run[k]):.0f} > {cost(lama[k]):.0f})"
                                  for k in ks if ok(run[k]) and ok(lama[k]) and cost(run[k]) > cost(lama[k])) or '–'
    diffs = '; '.join(f"{k[1].split('-')[1]}: {cost(a[k]):.0f} -> {cost(b[k]):.0f}" for k in both
                      if cost(a[k]) != cost(b[k])) or '–'
    gl = ['+' + k[1].split('-')[1] for k in ks if ok(b[k]) and not ok(a[k])]
    gl += ['-' + k[1].split('-')[1] for k in ks if ok(a[k]) and not ok(b[k])]
    print(f"| {d} ({len(ks)}) | {ca} / {cb} / {cf} / {cl} | {med([float(a[k]['wall_s']) for k in both])} / "
          f"{med([float(b[k]['wall_s']) for k in both])} ({len(both)}) | {med([cost(a[k]) for k in three], '{:.1f}')} / "
          f"{med([cost(b[k]) for k in three], '{:.1f}')} / {med([cost(lama[k]) for k in three], '{:.1f}')} ({len(three)}) | "
          f"{above(a)}; {above(b)} | {diffs} | {', '.join(gl) or '–'} |")
    for i, v in enumerate((len(ks), ca, cb, cf, cl)):
        tot[i] += v
print(f"| **total ({tot[0]})** | **{tot[1]} / {tot[2]} / {tot[3]} / {tot[4]}** | | | | | |")
