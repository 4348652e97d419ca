#!/usr/bin/env python3
"""Whole frames (cellrt_scaling's scaling_*.json): per shading, scene and worker count, the frame
seconds of `auto` and `bvh:packet`, Embree's fastest (embree:single or embree:packet8) and Embree's
time over each of the two (above 1: cellrt faster)."""
import json
import sys

print('| shading | scene | workers | `auto` s | `bvh:packet` s | Embree\'s fastest s | Embree ÷ `auto` | Embree ÷ `bvh:packet` |')
print('|---|---|--:|--:|--:|--:|--:|--:|')
for path in sys.argv[1:] or ['scaling_direct.json', 'scaling_ao.json']:
    cells = {}
    for r in json.load(open(path)):
        cells.setdefault((r['shading'], r['scene'], r['workers']), {})[r['config']] = r['seconds']
    for (shading, scene, workers), c in cells.items():
        e = min(c['embree:single'], c['embree:packet8'])
        name = 'packet8' if c['embree:packet8'] <= c['embree:single'] else 'single'
        print(f"| {shading} | {scene} | {workers} | {c['auto']:.3f} | {c['bvh:packet']:.3f} | {e:.3f} ({name}) | "
              f"{e / c['auto']:.2f} | {e / c['bvh:packet']:.2f} |")
