#!/usr/bin/env python3
"""Whole frames (cellrt_scaling's scaling_*.json): per shading, scene and worker count, each
config's frame seconds, Embree's fastest (embree:single or embree:packet8) and Embree ÷ auto."""
import json
import sys

for path in sys.argv[1:] or ['scaling_ao.json', 'scaling_diffuse.json']:
    rows = json.load(open(path))
    cells = {}
    for r in rows:
        cells.setdefault((r['shading'], r['scene'], r['workers']), {})[r['config']] = r['seconds']
    print('| shading | scene | workers | `auto` s | `bvh:paired` s | Embree\'s fastest s | Embree ÷ `auto` |')
    print('|---|---|--:|--:|--:|--:|--:|')
    for (shading, scene, workers), c in cells.items():
        e = min(c['embree:single'], c['embree:packet8'])
        name = 'packet8' if c['embree:packet8'] <= c['embree:single'] else 'single'
        print(f"| {shading} | {scene} | {workers} | {c['auto']:.3f} | {c['bvh:paired']:.3f} | {e:.3f} ({name}) | {e / c['auto']:.2f} |")
