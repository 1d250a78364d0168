#!/usr/bin/env python3
"""Issue 14, twenty-third round: per-domain table of a base CSV (the previous rounds' rows merged) against per-domain CSVs and a stopped driver's log lines."""
import csv, glob, re, statistics, sys
# usage: table.py BASE_CSV NEW_CSV_GLOB FIRST_PASS_LOG
base = {(r['domain'], r['problem']): r for r in csv.DictReader(open(sys.argv[1]))}
new = {}
for f in sorted(glob.glob(sys.argv[2])):
    for r in csv.DictReader(open(f)):
        new[(r['domain'], r['problem'])] = dict(r, src='csv')
for line in open(sys.argv[3]):
    m = re.match(r'(\S+)\s+(instance-\d+)\s+exit\s+(\d+)\s+([0-9.]+) s\s+\d+ KB\s+len\s+(-?\d+)', line)
    if not m: continue
    k = (m.group(1), m.group(2))
    if k in new: continue
    new[k] = {'solved': '1' if m.group(3) == '0' else '0', 'wall_s': m.group(4), 'plan_length': m.group(5),
              'plan_cost': None, 'stats': '', 'src': 'log'}
def ev(r):
    m = re.search(r'evaluated (\d+)', r['stats']); return int(m.group(1)) if m else None
doms = sorted({d for d, _ in new})
tb = tn = tr = 0
for d in doms:
    keys = sorted((k for k in new if k[0] == d), key=lambda k: int(k[1].split('-')[1]))
    allk = [k for k in base if k[0] == d]
    src = 'log' if all(new[k]['src'] == 'log' for k in keys) else 'csv'
    cb = sum(1 for k in keys if base[k]['solved'] == '1'); cn = sum(1 for k in keys if new[k]['solved'] == '1')
    tb += cb; tn += cn; tr += len(keys)
    both = [k for k in keys if base[k]['solved'] == '1' and new[k]['solved'] == '1']
    mb = statistics.median(float(base[k]['wall_s']) for k in both) if both else float('nan')
    mn = statistics.median(float(new[k]['wall_s']) for k in both) if both else float('nan')
    if src == 'csv':
        same = sum(1 for k in both if ev(base[k]) == ev(new[k])); sd = f"{same} / {len(both) - same}"
    else:
        sd = 'n/a (log only)'
    diffs = []
    for k in both:
        b = base[k]['plan_cost'] if new[k]['plan_cost'] else base[k]['plan_length']
        n = new[k]['plan_cost'] or new[k]['plan_length']
        if b != n: diffs.append(f"{k[1].replace('instance-','')}: {b} -> {n}")
    gained = ['+' + k[1].replace('instance-', '') for k in keys if new[k]['solved'] == '1' and base[k]['solved'] != '1']
    lost = ['-' + k[1].replace('instance-', '') for k in keys if new[k]['solved'] != '1' and base[k]['solved'] == '1']
    part = '' if len(keys) == len(allk) else f" of {len(allk)}"
    print(f"| {d} ({len(keys)}{part}) | {cb} / {cn} | {mb:.3f} -> {mn:.3f} ({len(both)}) | {sd} | {'; '.join(diffs) or '–'} | {', '.join(gained + lost) or '–'} |")
print(f"| **reached: {tr}** | **{tb} / {tn}** | | | | |")
