#!/usr/bin/env python3
"""From run.sh's paired_*.json: per ray kind, scene and kind of ray (first: closest hit; second: any
hit for frame, random and ao, closest hit for diffuse bounces), `bvh` and `bvh:paired` over Embree's
fastest (the lesser time of embree:single and embree:packet8) in the same run, medians over the
runs, and paired ÷ single."""
import collections
import json
import statistics
import sys

acc = collections.defaultdict(list)
for path in sys.argv[1:]:
    rows = json.load(open(path))
    by = collections.defaultdict(dict)
    for r in rows:  # the two forests share a name: told apart by their triangles
        scene = r['scene'] if r['scene'] != 'forest' else f"forest {r['triangles']:,}"
        by[scene][r['config']] = r
    for scene, c in by.items():
        for kind in ('primary', 'shadow'):
            e = min(c['embree:single'][kind + '_seconds'], c['embree:packet8'][kind + '_seconds'])
            for config in ('bvh', 'bvh:paired'):
                acc[(rows[0]['rays'], scene, kind, config)].append(e / c[config][kind + '_seconds'])
print('| rays | scene | kind | `bvh` ÷ Embree | `bvh:paired` ÷ Embree | paired ÷ single |')
print('|---|---|---|--:|--:|--:|')
for key in sorted({k[:3] for k in acc}):
    one, two = statistics.median(acc[key + ('bvh',)]), statistics.median(acc[key + ('bvh:paired',)])
    kind = 'first' if key[2] == 'primary' else 'second'
    print(f'| {key[0]} | {key[1]} | {kind} | {one:.2f} | {two:.2f} | {two / one:.3f} |')
