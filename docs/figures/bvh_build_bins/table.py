#!/usr/bin/env python3
"""run.sh's build runs: per threads and scene, the BVH's build time (median of the rounds, each the
median of five builds) before and after, after ÷ before, and each side's ratio to Embree's build in
its own runs."""
import glob
import json
import re
import statistics

cells = {}
for f in sorted(glob.glob('b_*_t*_*.json')):
    who, threads = re.search(r'b_(old|new)_t(\d+)_', f).groups()
    runs = json.load(open(f))
    emb = {r['scene']: r['build_seconds'] for r in runs if r['config'] == 'embree:single'}
    for r in runs:
        if r['config'] != 'bvh':
            continue
        c = cells.setdefault((int(threads), r['scene']), {'old': [], 'new': [], 'rold': [], 'rnew': []})
        c[who].append(r['build_seconds'])
        c['r' + who].append(r['build_seconds'] / emb[r['scene']])
print('| threads | scene | before ms | after ms | after ÷ before | ÷ Embree before | ÷ Embree after |')
print('|--:|---|--:|--:|--:|--:|--:|')
for (t, sc), c in sorted(cells.items()):
    o, n = statistics.median(c['old']), statistics.median(c['new'])
    print(f"| {t} | {sc} | {1e3 * o:.1f} | {1e3 * n:.1f} | {n / o:.3f} | {statistics.median(c['rold']):.2f} | "
          f"{statistics.median(c['rnew']):.2f} |")
