#!/usr/bin/env python3
"""The BIH builds on 1 and 2 threads, c0bff76 (old) against the empty-space cuts as tasks and the
parallel partition (new), four rounds in turn (run.sh; docs/BUILD_SPEED.md, "Sixteen threads: the
BIH's task tree"). Per side, the median of its runs' medians of five builds; per round, the
two-thread speed-up."""
import collections
import glob
import json
import os
import statistics as st
import sys

# table.py [DIR [CONFIG...]]: the runs in DIR (this folder's by default), the configurations named
# (by default the BIH's two builds and Embree's).
here = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
configs = sys.argv[2:] or ['bih@split=sah', 'bih', 'embree']
runs = collections.defaultdict(list)
for f in glob.glob(os.path.join(here, '*.json')):
    v, t, r = os.path.basename(f)[:-5].split('.')
    for x in json.load(open(f)):
        runs[(v, int(t[1:]), x['scene'], x['config'])].append((int(r[1:]), x['build_seconds']))

print('| structure | scene | old: 1 / 2 threads ms, speed-up | new | 1 thread, new ÷ old | 2 threads, new ÷ old | speed-up per round, old → new |')
print('|---|---|---|---|--:|--:|---|')
for c in configs:
    for s in ('sponza', 'sibenik', 'bunny', 'teapot', 'forest'):
        m = {(v, t): st.median(b for _, b in runs[(v, t, s, c)]) for v in ('old', 'new') for t in (1, 2)}
        if not all(m.values()):
            continue
        per_round = {}
        for v in ('old', 'new'):
            one, two = dict(runs[(v, 1, s, c)]), dict(runs[(v, 2, s, c)])
            per_round[v] = ', '.join(f'{one[r] / two[r]:.2f}' for r in sorted(one))
        cells = [f'{m[(v, 1)] * 1e3:.1f} / {m[(v, 2)] * 1e3:.1f}, {m[(v, 1)] / m[(v, 2)]:.2f}' for v in ('old', 'new')]
        print(f"| {c} | {s} | {cells[0]} | {cells[1]} | {m[('new', 1)] / m[('old', 1)]:.3f} | "
              f"{m[('new', 2)] / m[('old', 2)]:.3f} | {per_round['old']} → {per_round['new']} |")
