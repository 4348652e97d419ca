#!/usr/bin/env python3
"""run.sh's build runs: per threads, scene and config, the median build time of the runs (ms), its ratio
to Embree's in the same runs, and the structure's memory (MiB)."""
import json
import re
import statistics
import sys

cells = {}
for path in sys.argv[1:]:
    threads = int(re.search(r'builds_t(\d+)_', path).group(1))
    runs = json.load(open(path))
    emb = {r['scene']: r['build_seconds'] for r in runs if r['config'] == 'embree:single'}
    for r in runs:
        c = cells.setdefault((threads, r['scene'], r['config']), {'ms': [], 'ratio': [], 'mib': []})
        c['ms'].append(1e3 * r['build_seconds'])
        c['ratio'].append(r['build_seconds'] / emb[r['scene']])
        c['mib'].append(r['memory_mib'])
print('| threads | scene | config | build ms | ÷ Embree | memory MiB |')
print('|--:|---|---|--:|--:|--:|')
for (t, sc, cfg), c in cells.items():
    print(f"| {t} | {sc} | {cfg} | {statistics.median(c['ms']):.1f} | {statistics.median(c['ratio']):.2f} | "
          f"{statistics.median(c['mib']):.2f} |")
