#!/usr/bin/env python3
"""From ab_compare.py's files: per scene and config, its speed over Embree's fastest (the lesser time of
embree:single and embree:packet8) in the same run, the median (range) of each side's runs, and the
median of new over the median of old. Dividing by Embree in the same run takes out most of the
machine's slow and fast spells, which move whole runs."""
import json
import statistics
import sys

for path in sys.argv[1:]:
    d = json.load(open(path))
    acc = {}
    for run in d['runs']:
        rows = {(r['scene'], r['config']): r['primary_seconds'] + r['shadow_seconds'] for r in run['rows']}
        for (scene, config), t in rows.items():
            if config.startswith('embree'):
                continue
            embree = min(rows[(scene, 'embree:single')], rows[(scene, 'embree:packet8')])
            acc.setdefault((scene, config), {'a': [], 'b': []})[run['side']].append(embree / t)
    print(f"{path}: --rays {d['args'][d['args'].index('--rays') + 1]}")
    print('| scene | config | old ÷ Embree | new ÷ Embree | new ÷ old |')
    print('|---|---|--:|--:|--:|')
    for (scene, config), v in acc.items():
        a, b = statistics.median(v['a']), statistics.median(v['b'])
        fmt = lambda x, s: f'{x:.2f} ({min(s):.2f}–{max(s):.2f})'
        print(f"| {scene} | `{config}` | {fmt(a, v['a'])} | {fmt(b, v['b'])} | {b / a:.3f} |")
