#!/usr/bin/env python3
"""Whole frames (cellrt_scaling's scaling_*.json): per shading, scene and worker count, the frame
seconds of `auto` and `bvh:packet`, Embree's fastest configuration and Embree's time over `auto`'s."""
import json
import sys

for path in sys.argv[1:] or ['scaling_ao.json', 'scaling_diffuse.json']:
    rows = json.load(open(path))
    cells = {}
    for r in rows:
        cells.setdefault((r['shading'], r['scene'], r['workers']), {})[r['config']] = r['seconds']
    print('| shading | scene | workers | `auto` s | `bvh:packet` s | Embree\'s fastest s | Embree ÷ `auto` |')
    print('|---|---|--:|--:|--:|--:|--:|')
    for (shading, scene, workers), c in cells.items():
        name, e = min(((k, v) for k, v in c.items() if k.startswith('embree')), key=lambda kv: kv[1])
        print(f"| {shading} | {scene} | {workers} | {c['auto']:.3f} | {c['bvh:packet']:.3f} | "
              f"{e:.3f} ({name.split(':')[1]}) | {e / c['auto']:.2f} |")
