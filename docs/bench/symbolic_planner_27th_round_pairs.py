#!/usr/bin/env python3
"""Issue 14, twenty-seventh round: instances run by binary in turn through the driver (the rows of
symbolic_planner_27th_round_pairs.csv, the planner column naming the binary), side by side: wall
time, plan cost (length), evaluations, and the h^2 tests of the restarted hill-climbing (`--stats`).
usage: symbolic_planner_27th_round_pairs.py PAIRS_CSV LABEL..."""
import csv, re, sys

labels = sys.argv[2:]
rows = {(r['domain'], r['problem'], r['planner']): r for r in csv.DictReader(open(sys.argv[1]))}
num = lambda k: (k[0], int(k[1].split('-')[1]))
print('| instance | ' + ' | '.join(f'{l}: wall s, cost, evaluations, h^2 tests / dead' for l in labels) + ' |')
print('|---|' + '---|' * len(labels))
for k in sorted({(a, b) for a, b, _ in rows}, key=num):
    cells = []
    for l in labels:
        r = rows.get(k + (l,))
        if r is None:
            cells.append('–')
            continue
        s = r['stats']
        ev = re.search(r'evaluated (\d+)', s)
        t = re.search(r'restarts \d+ \((\d+) tests; (\d+) dead ends\)', s)
        cost = r['plan_cost'] or r['plan_length']
        cells.append(f"{float(r['wall_s']):.3f}, {cost if r['solved'] == '1' else 'x'}, "
                     f"{ev.group(1) if ev else '?'}, {t.group(1) + ' / ' + t.group(2) if t else '?'}")
    print(f'| {k[0]}-{k[1].split("-")[1]} | ' + ' | '.join(cells) + ' |')
