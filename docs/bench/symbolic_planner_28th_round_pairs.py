# Table of pairs.sh's CSV: per instance, task-clock and elapsed ms of A and B (mean of the two
# rounds; each round perf stat -r N and N back-to-back runs), B - A, whether the plans are the same;
# then per domain the medians of elapsed against FF 2.3's reference wall time.
import csv, sys, statistics as st, collections
rows = list(csv.DictReader(open(sys.argv[1])))
refs = {}
for s in ('pddl', 'pddl-more'):
    for r in csv.DictReader(open(f'tests/data/benchmarks/{s}/reference_results.csv')):
        if r['planner'] == 'ff-v2.3' and r['solved'] == '1':
            refs[f"{s}/{r['domain']}/{r['problem']}"] = float(r['wall_s']) * 1000
by = collections.OrderedDict()
for r in rows:
    by.setdefault(r['instance'], {'A': [], 'B': [], 'eA': [], 'eB': [], 'same': r['same_plan'], 'load': []})
    d = by[r['instance']]
    d[r['bin']].append(float(r['task_clock_ms']))
    d['e' + r['bin']].append(float(r['elapsed_ms']))
    d['load'].append(float(r['load1']))
print('| instance | task-clock ms A / B | B - A | elapsed ms A / B | FF ms | same plan | load |')
print('|---|---|---|---|---|---|---|')
dom = collections.OrderedDict()
for k, d in by.items():
    a, b, ea, eb = (st.mean(d[x]) for x in ('A', 'B', 'eA', 'eB'))
    # pddl-more problem paths may be <domain>/instance-N/instance-N
    parts = k.split('/')
    key = f'{parts[0]}/{parts[1]}/{parts[-1]}'
    ff = refs.get(key)
    print(f"| {parts[0]}/{parts[1]}/{parts[-1]} | {a:.2f} / {b:.2f} | {b - a:+.2f} | {ea:.2f} / {eb:.2f} | {'%.0f' % ff if ff else '–'} | {'yes' if d['same'] == '1' else 'NO'} | {min(d['load']):.1f}-{max(d['load']):.1f} |")
    dd = dom.setdefault(f'{parts[0]}/{parts[1]}', {'ta': [], 'tb': [], 'ea': [], 'eb': [], 'ff': [], 'n': 0})
    dd['ta'].append(a); dd['tb'].append(b)
    if ff:
        dd['ea'].append(ea); dd['eb'].append(eb); dd['ff'].append(ff)
print()
print('| domain (instances) | median task-clock ms A / B | median elapsed ms A / B / FF (n FF solves) |')
print('|---|---|---|')
for k, dd in dom.items():
    e = f"{st.median(dd['ea']):.2f} / {st.median(dd['eb']):.2f} / {st.median(dd['ff']):.1f} ({len(dd['ff'])})" if dd['ff'] else '–'
    print(f"| {k} ({len(dd['ta'])}) | {st.median(dd['ta']):.2f} / {st.median(dd['tb']):.2f} | {e} |")
