#!/usr/bin/env python3
"""compare.py BASE_PREFIX NEW_PREFIX: per-domain coverage, medians, same evals, gained/lost."""
import csv, glob, os, re, statistics, sys
base_prefix, new_prefix = sys.argv[1], sys.argv[2]
def load(prefix):
    rows = {}
    for f in glob.glob(prefix + '_*.csv'):
        if f.endswith('_summary.md'): continue
        for r in csv.DictReader(open(f)):
            rows[(r['domain'], r['problem'])] = r
    return rows
B, N = load(base_prefix), load(new_prefix)
def ev(r):
    m = re.search(r'evaluated (\d+)', r['stats']); return int(m.group(1)) if m else None
doms = sorted({d for d, _ in N})
tb = tn = 0
for d in doms:
    keys = sorted(k for k in N if k[0] == d)
    cb = sum(1 for k in keys if k in B and B[k]['solved'] == '1'); cn = sum(1 for k in keys if N[k]['solved'] == '1')
    tb += cb; tn += cn
    both = [k for k in keys if k in B and B[k]['solved'] == '1' and N[k]['solved'] == '1']
    mb = statistics.median(float(B[k]['wall_s']) for k in both) if both else float('nan')
    mn = statistics.median(float(N[k]['wall_s']) for k in both) if both else float('nan')
    same = sum(1 for k in both if ev(B[k]) == ev(N[k])); differ = len(both) - same
    gained = [k[1].replace('instance-', '') for k in keys if N[k]['solved'] == '1' and not (k in B and B[k]['solved'] == '1')]
    lost = [k[1].replace('instance-', '') for k in keys if N[k]['solved'] != '1' and k in B and B[k]['solved'] == '1']
    costs = []
    for k in both:
        cbk, cnk = B[k]['plan_cost'], N[k]['plan_cost']
        if cbk != cnk: costs.append(f"{k[1].replace('instance-','')}: {cbk} -> {cnk}")
    gl = ', '.join(['+' + g for g in gained] + ['-' + l for l in lost]) or '–'
    print(f"| {d} ({len(keys)}) | {cb} / {cn} | {mb:.3f} -> {mn:.3f} ({len(both)}) | {same} / {differ} | {'; '.join(costs) or '–'} | {gl} |")
print(f"| **reached: {len(N)}** | **{tb} / {tn}** | | | | |")
