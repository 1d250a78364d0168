#!/usr/bin/env python3
"""Issue 14, twenty-fourth round: per-domain table of main against this branch (per-domain driver
CSVs, run alternately), with the FF 2.3 and LAMA-first references of the set.
usage: symbolic_planner_24th_round_compare.py SET_DIR MAIN_CSV_GLOB BRANCH_CSV_GLOB"""
import csv, glob, re, statistics, sys


def rows(pattern):
    out = {}
    for f in sorted(glob.glob(pattern)):
        for r in csv.DictReader(open(f)):
            out[(r['domain'], r['problem'])] = r
    return out


def evaluations(r):
    m = re.search(r'evaluated (\d+)', r.get('stats', ''))
    return int(m.group(1)) if m else None


def median(xs):
    return f"{statistics.median(xs):.3f}" if xs else '–'


ref = {}
for r in csv.DictReader(open(sys.argv[1] + '/reference_results.csv')):
    ref[(r['domain'], r['problem'], r['planner'])] = r
main, new = rows(sys.argv[2]), rows(sys.argv[3])
keys = sorted(set(main) & set(new), key=lambda k: (k[0], int(k[1].split('-')[1])))
solved = lambda r: r is not None and r['solved'] == '1'
print('| domain (n) | coverage main / branch | FF / LAMA | median wall s main -> branch (n both) | '
      'same evaluations / differ | cost or length, where it differs | gained / lost |')
print('|---|---|---|---|---|---|---|')
tot = [0, 0, 0, 0, 0]
for d in sorted({k[0] for k in keys}):
    ks = [k for k in keys if k[0] == d]
    cm = sum(solved(main[k]) for k in ks)
    cn = sum(solved(new[k]) for k in ks)
    ff = sum(solved(ref.get((d, k[1], 'ff-v2.3'))) for k in ks)
    lama = sum(solved(ref.get((d, k[1], 'fd-lama-first'))) for k in ks)
    both = [k for k in ks if solved(main[k]) and solved(new[k])]
    same = sum(1 for k in both if evaluations(main[k]) == evaluations(new[k]))
    diffs = []
    for k in both:
        b = main[k]['plan_cost'] or main[k]['plan_length']
        n = new[k]['plan_cost'] or new[k]['plan_length']
        if b != n:
            diffs.append(f"{k[1].replace('instance-', '')}: {b} -> {n}")
    gl = ['+' + k[1].replace('instance-', '') for k in ks if solved(new[k]) and not solved(main[k])]
    gl += ['-' + k[1].replace('instance-', '') for k in ks if solved(main[k]) and not solved(new[k])]
    mm = median([float(main[k]['wall_s']) for k in both])
    mn = median([float(new[k]['wall_s']) for k in both])
    print(f"| {d} ({len(ks)}) | {cm} / {cn} | {ff} / {lama} | {mm} -> {mn} ({len(both)}) | {same} / {len(both) - same} "
          f"| {'; '.join(diffs) or '–'} | {', '.join(gl) or '–'} |")
    for i, v in enumerate((len(ks), cm, cn, ff, lama)):
        tot[i] += v
print(f"| **total ({tot[0]})** | **{tot[1]} / {tot[2]}** | **{tot[3]} / {tot[4]}** | | | | |")
