#!/usr/bin/env python3
"""Whole frames (cellrt_scaling, 384 x 384, AO and diffuse): Embree's fastest of its single rays and
packets of eight and sixteen over auto's and bvh:packet's frame time, one and two workers.

    table.py [FOLDER]    (the folder of scaling_ao.json and scaling_diffuse.json; default: this one)"""
import json
import os
import sys

HERE = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
SCENES = ['sponza', 'sibenik', 'bunny', 'teapot']
print('| shading | workers | config | ' + ' | '.join(SCENES) + ' |\n|---|--:|---|' + '--:|' * len(SCENES))
for sh in ['ao', 'diffuse']:
    pts = json.load(open(os.path.join(HERE, f'scaling_{sh}.json')))
    for w in (1, 2):
        for config in ('auto', 'bvh:packet'):
            cells = []
            for sc in SCENES:
                t = {p['config']: p['seconds'] for p in pts if p['scene'] == sc and p['workers'] == w}
                embree = min(v for k, v in t.items() if k.startswith('embree'))
                cells.append(f"{embree / t[config]:.2f}")
            print(f'| {sh} | {w} | `{config}` | ' + ' | '.join(cells) + ' |')
