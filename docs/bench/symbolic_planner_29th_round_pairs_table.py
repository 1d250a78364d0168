#!/usr/bin/env python3
"""Issue 14, twenty-ninth round: main (A) against this branch (B) per instance from the pairs CSVs:
the mean CPU and wall seconds of each binary's runs, whether every B run had A's plan, evaluations
and expansions. usage: pairs_table.py CSV..."""
import csv, sys, statistics
rows = [r for f in sys.argv[1:] for r in csv.DictReader(open(f))]
order, by = [], {}
for r in rows:
    k = r['instance']
    if k not in by: order.append(k); by[k] = {'A': [], 'B': [], 'same': [], 'ev': r['evaluated']}
    by[k][r['bin']].append((float(r['wall_s']), float(r['cpu_s'])))
    if r['bin'] == 'B': by[k]['same'].append(r['same'])
print('| instance | evaluations | runs per binary | CPU s main / new (mean) | wall s main / new (mean) | new / main CPU | same plan and counts |')
print('|---|---|---|---|---|---|---|')
for k in order:
    a, b = by[k]['A'], by[k]['B']
    n = min(len(a), len(b))
    if n == 0 or len(a) != len(b): continue
    ca, cb = statistics.mean(x[1] for x in a), statistics.mean(x[1] for x in b)
    wa, wb = statistics.mean(x[0] for x in a), statistics.mean(x[0] for x in b)
    same = 'yes' if all(s == '1' for s in by[k]['same']) else 'NO'
    print(f"| {k} | {by[k]['ev']} | {n} | {ca:.3f} / {cb:.3f} | {wa:.3f} / {wb:.3f} | {cb / ca if ca else float('nan'):.2f} | {same} |")
