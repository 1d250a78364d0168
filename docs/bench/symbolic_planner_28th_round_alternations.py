# Issue 14, twenty-eighth round: the alternations (rounds 0-4; per round and domain one driver
# call of main, then one of the new binary, the lock per instance): per domain and round, the
# median wall and CPU time of each over the instances FF 2.3 solves, against FF's median.
import csv, sys, statistics as st
rows = list(csv.DictReader(open(sys.argv[1])))
ff = {(r['domain'], r['problem']): float(r['wall_s']) for r in
      csv.DictReader(open('tests/data/benchmarks/pddl/reference_results.csv'))
      if r['planner'] == 'ff-v2.3' and r['solved'] == '1'}
print('| domain (n) | FF median ms | round | main: median wall / CPU ms | new: median wall / CPU ms | wall above FF: main / new |')
print('|---|---|---|---|---|---|')
doms = []
for r in rows:
    if r['domain'] not in doms: doms.append(r['domain'])
summary = {}
for d in doms:
    keys = sorted({r['problem'] for r in rows if r['domain'] == d and (d, r['problem']) in ff}, key=lambda p: int(p.split('-')[1]))
    fmed = st.median(ff[(d, p)] for p in keys) * 1000
    for rnd in sorted({r['round'] for r in rows}):
        cell = {}
        for b in ('main', 'new'):
            sel = [r for r in rows if r['domain'] == d and r['round'] == rnd and r['binary'] == b and r['problem'] in keys]
            assert all(r['solved'] == '1' for r in sel)
            w = st.median(float(r['wall_s']) for r in sel) * 1000
            c = st.median(float(r['cpu_s']) for r in sel) * 1000
            cell[b] = (w, c)
            summary.setdefault((d, b), []).append(w)
        print(f"| {d} ({len(keys)}) | {fmed:.1f} | {rnd} | {cell['main'][0]:.1f} / {cell['main'][1]:.1f} | {cell['new'][0]:.1f} / {cell['new'][1]:.1f} | "
              f"{'yes' if cell['main'][0] > fmed else 'no'} / {'yes' if cell['new'][0] > fmed else 'no'} |")
