#!/usr/bin/env python3
"""frames_ab.sh's runs: per shading, scene, workers and config, the median frame seconds of the old
binary (a) and the new (b), new ÷ old, and each side's median ratio to Embree's packet8 in its runs."""
import json
import re
import statistics
import sys

cells = {}
for path in sys.argv[1:]:
    who = re.search(r'frames_([ab])_', path).group(1)
    runs = json.load(open(path))
    emb = {(r['shading'], r['scene'], r['workers']): r['seconds'] for r in runs if r['config'] == 'embree:packet8'}
    for r in runs:
        key = (r['shading'], r['scene'], r['workers'], r['config'])
        c = cells.setdefault(key, {'a': [], 'b': [], 'ra': [], 'rb': []})
        c[who].append(r['seconds'])
        c['r' + who].append(emb[key[:3]] / r['seconds'])
print('| shading | scene | workers | config | old s | new s | new ÷ old | Embree ÷ old | Embree ÷ new |')
print('|---|---|--:|---|--:|--:|--:|--:|--:|')
for (sh, sc, w, cfg), c in sorted(cells.items()):
    a, b = statistics.median(c['a']), statistics.median(c['b'])
    print(f"| {sh} | {sc} | {w} | {cfg} | {a:.4f} | {b:.4f} | {b / a:.3f} | "
          f"{statistics.median(c['ra']):.2f} | {statistics.median(c['rb']):.2f} |")
