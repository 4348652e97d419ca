#!/usr/bin/env python3
"""frames.sh's runs: per shading, scene and workers, each config's median frame seconds, Embree's packets
of eight over it (speed ratio, median of the rounds) and `auto@packets=bvh` over `auto` (time ratio)."""
import json
import statistics
import sys

cells = {}
for path in sys.argv[1:]:
    runs = json.load(open(path))
    emb = {(r['shading'], r['scene'], r['workers']): r['seconds'] for r in runs if r['config'] == 'embree:packet8'}
    auto = {(r['shading'], r['scene'], r['workers']): r['seconds'] for r in runs if r['config'] == 'auto'}
    for r in runs:
        key = (r['shading'], r['scene'], r['workers'])
        c = cells.setdefault(key, {}).setdefault(r['config'], {'s': [], 'emb': [], 'auto': []})
        c['s'].append(r['seconds'])
        c['emb'].append(emb[key] / r['seconds'])
        c['auto'].append(r['seconds'] / auto[key])
configs = ['auto', 'auto@packets=bvh', 'bvh:packet', 'embree:packet8']
print('| shading | scene | workers | ' + ' | '.join(f'`{c}` s (Embree ÷ it)' for c in configs) +
      ' | `auto@packets=bvh` ÷ `auto`, time (rounds) |')
print('|---|---|--:|' + '--:|' * (len(configs) + 1))
for (sh, sc, w), by in sorted(cells.items()):
    row = [f"{statistics.median(by[c]['s']):.4f} ({statistics.median(by[c]['emb']):.2f})" for c in configs]
    r = by['auto@packets=bvh']['auto']
    print(f"| {sh} | {sc} | {w} | " + ' | '.join(row) +
          f" | {statistics.median(r):.3f} ({min(r):.3f}–{max(r):.3f}) |")
