#!/usr/bin/env python3
"""Issue 14: the IPC benchmark driver's CSVs (tamp_symbolic_planner_ipc_bench --out), compared.

One tool for every round (it replaces the per-round compare and table scripts of docs/bench/):

  ipc_compare.py compare BASE NEW
      two planners' rows, instance by instance: solved, plan length, cost and the evaluations of
      the statistics line (the search's decisions: the same where nothing depends on time), the
      rows that differ listed with their wall times, the domains' median wall times on the
      instances both solve, and the instances gained and lost.
  ipc_compare.py table SET_DIR CSVS
      one planner's rows against the set's FF 2.3 and LAMA-first references
      (SET_DIR/reference_results.csv), by the issue's aims: coverage per domain against FF's
      (and the instances FF solves that we do not), in total against LAMA-first's, median wall
      time against FF's on the instances both solve, median plan length (cost) against
      LAMA-first's on the instances both solve and the instances dearer than LAMA-first's.
  ipc_compare.py coverage LABEL=CSVS ...
      solved instances per domain and in total, one column a label (a round, a binary).

CSVS / BASE / NEW: a glob (quoted), a CSV file or a folder (every *.csv in it); several may be
joined with commas. Rows are keyed by (domain, problem); a later file's row replaces an earlier
one's.
"""
import argparse
import csv
import glob
import os
import re
import statistics
import sys


def csv_files(spec):
    files = []
    for part in spec.split(','):
        if os.path.isdir(part):
            files += sorted(glob.glob(os.path.join(part, '*.csv')))
        else:
            files += sorted(glob.glob(part))
    if not files:
        sys.exit(f'ipc_compare.py: no CSV matches {spec!r}')
    return files


def load(spec):
    rows = {}
    for f in csv_files(spec):
        with open(f, newline='') as fh:
            for r in csv.DictReader(fh):
                if 'domain' in r and 'problem' in r and 'solved' in r:
                    rows[(r['domain'], r['problem'])] = r
    return rows


def num(key):
    m = re.search(r'(\d+)$', key[1])
    return int(m.group(1)) if m else 0


def short(key):
    return str(num(key))


def evaluations(r):
    m = re.search(r'evaluated (\d+)', r.get('stats') or '')
    return m.group(1) if m else None


def solved(r):
    return r is not None and r.get('solved') == '1'


def cost(r):
    return float(r.get('plan_cost') or r['plan_length'])


def median(xs, fmt='{:.3f}'):
    return fmt.format(statistics.median(xs)) if xs else '–'


def compare(base, new, out=sys.stdout):
    same, gained, lost, missing = 0, [], [], []
    for d in sorted({k[0] for k in new}):
        ks = sorted((k for k in new if k[0] == d), key=num)
        missing += [f'{d}-{short(k)}' for k in ks if k not in base]
        ks = [k for k in ks if k in base]
        both = [k for k in ks if solved(base[k]) and solved(new[k])]
        mb = median([float(base[k]['wall_s']) for k in both])
        mn = median([float(new[k]['wall_s']) for k in both])
        diffs = []
        for k in ks:
            b, n = base[k], new[k]
            a = (b['solved'], b['plan_length'], b.get('plan_cost', ''), evaluations(b))
            c = (n['solved'], n['plan_length'], n.get('plan_cost', ''), evaluations(n))
            if not solved(b) and solved(n):
                gained.append(f'{d}-{short(k)}')
            if solved(b) and not solved(n):
                lost.append(f'{d}-{short(k)}')
            if a == c:
                same += 1
            else:
                diffs.append(f"{short(k)}: {'/'.join(map(str, a))} {float(b['wall_s']):.2f}s -> "
                             f"{'/'.join(map(str, c))} {float(n['wall_s']):.2f}s")
        print(f'{d}: {len(ks) - len(diffs)} of {len(ks)} the same; median wall on both solved '
              f'({len(both)}) {mb} -> {mn} s' + ('; ' + '; '.join(diffs) if diffs else ''), file=out)
    n_base = sum(solved(r) for k, r in base.items() if k in new)
    n_new = sum(solved(r) for r in new.values())
    print(f'rows the same (solved/length/cost/evaluations): {same} of {len(new)}; solved {n_base} -> '
          f'{n_new}; gained {gained}; lost {lost}' + (f'; not in base {missing}' if missing else ''),
          file=out)


def table(set_dir, ours, out=sys.stdout):
    ref = {}
    with open(os.path.join(set_dir, 'reference_results.csv'), newline='') as fh:
        for r in csv.DictReader(fh):
            ref[(r['domain'], r['problem'], r['planner'])] = r
    print('| domain (n) | coverage ours / FF / LAMA | FF solves, we do not | median wall s ours / FF '
          '(n both) | time aim | median length ours / LAMA (n both) | dearer than LAMA-first |', file=out)
    print('|---|---|---|---|---|---|---|', file=out)
    tot = [0] * 4
    for d in sorted({k[0] for k in ours}):
        ks = sorted((k for k in ours if k[0] == d), key=num)
        ff = {k: ref.get((d, k[1], 'ff-v2.3')) for k in ks}
        la = {k: ref.get((d, k[1], 'fd-lama-first')) for k in ks}
        c = [sum(solved(x[k]) for k in ks) for x in (ours, ff, la)]
        ff_only = ', '.join(short(k) for k in ks if solved(ff[k]) and not solved(ours[k])) or '–'
        bf = [k for k in ks if solved(ours[k]) and solved(ff[k])]
        bl = [k for k in ks if solved(ours[k]) and solved(la[k])]
        mo = [float(ours[k]['wall_s']) for k in bf]
        mf = [float(ff[k]['wall_s']) for k in bf]
        aim = '–' if not bf else ('met' if statistics.median(mo) <= statistics.median(mf) else '**missed**')
        dear = ', '.join(f'{short(k)} ({cost(ours[k]):.0f} > {cost(la[k]):.0f})' for k in bl
                         if cost(ours[k]) > cost(la[k])) or '–'
        print(f'| {d} ({len(ks)}) | {c[0]} / {c[1]} / {c[2]} | {ff_only} | {median(mo)} / {median(mf)} '
              f'({len(bf)}) | {aim} | {median([cost(ours[k]) for k in bl], "{:.1f}")} / '
              f'{median([cost(la[k]) for k in bl], "{:.1f}")} ({len(bl)}) | {dear} |', file=out)
        for i, v in enumerate([len(ks)] + c):
            tot[i] += v
    print(f'| **total ({tot[0]})** | **{tot[1]} / {tot[2]} / {tot[3]}** | | | | | |', file=out)


def coverage(labelled, out=sys.stdout):
    names = [name for name, _ in labelled]
    doms = sorted({k[0] for _, rows in labelled for k in rows})
    print('| domain | ' + ' | '.join(names) + ' |', file=out)
    print('|---|' + '---|' * len(names), file=out)
    tot = [[0, 0] for _ in names]
    for d in doms:
        cells = []
        for i, (_, rows) in enumerate(labelled):
            ks = [k for k in rows if k[0] == d]
            s = sum(solved(rows[k]) for k in ks)
            tot[i][0] += s
            tot[i][1] += len(ks)
            cells.append(f'{s} / {len(ks)}' if ks else '–')
        print(f'| {d} | ' + ' | '.join(cells) + ' |', file=out)
    print('| **total** | ' + ' | '.join(f'**{s} / {n}**' for s, n in tot) + ' |', file=out)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest='cmd', required=True)
    c = sub.add_parser('compare', help='two planners, instance by instance')
    c.add_argument('base')
    c.add_argument('new')
    t = sub.add_parser('table', help='one planner against the FF 2.3 and LAMA-first references')
    t.add_argument('set_dir')
    t.add_argument('csvs')
    v = sub.add_parser('coverage', help='solved instances per domain, a column a LABEL=CSVS')
    v.add_argument('labelled', nargs='+')
    a = p.parse_args(argv)
    if a.cmd == 'compare':
        compare(load(a.base), load(a.new))
    elif a.cmd == 'table':
        table(a.set_dir, load(a.csvs))
    else:
        pairs = []
        for spec in a.labelled:
            name, sep, files = spec.partition('=')
            if not sep:
                p.error(f'coverage takes LABEL=CSVS, not {spec!r}')
            pairs.append((name, load(files)))
        coverage(pairs)


if __name__ == '__main__':
    main()
